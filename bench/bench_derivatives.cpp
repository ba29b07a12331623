// The generated constrained_dynamics_derivatives against central finite
// differences of the generated prox_pv and against Pinocchio 3.7, per case of
// PROXGEN_BENCH_DERIVATIVE_CASES (bench/derivatives.cmake), in one run:
//
//   <case>/cdd/generated          constrained_dynamics_derivatives (qdd, lambda and
//                                 their six derivative blocks)
//   <case>/fd/generated_prox_pv   central differences of prox_pv, 6 nv calls: per
//                                 tangent direction k, q (+) h e_k and q (+) -h e_k
//                                 (test::integrate of tests/numerics.hpp, the
//                                 manifold step the derivatives' convention uses;
//                                 neither the generated code nor the runtime nor
//                                 the generic library has one), v +- h e_k, tau +- h
//                                 e_k; the 2 nv integrations, their heap VecX and
//                                 the conversion to the solver's Scalar are in the
//                                 timed call. The nominal qdd, lambda are not
//                                 computed (6 nv calls, not 6 nv + 1).
//   <case>/fd/integrate_only      the 2 nv integrations of that variant alone, to
//                                 read their share of it
//   <case>/cdd/pinocchio          pinocchio::constraintDynamics followed by
//                                 pinocchio::computeConstraintDynamicsDerivatives
//                                 (bench_pinocchio.cpp: the constraint models of
//                                 pin_caba / pin_pv, mu = 1/proxgen's mu,
//                                 max_iter = K, accuracy 0), where CMake found
//                                 Pinocchio (PROXGEN_BENCH_PINOCCHIO)
//   <case>/idd/generated          inverse_dynamics_derivatives(q, v, a, nullptr):
//                                 dtau/dq and dtau/dv of RNEA, the kinematics pass
//                                 and the tangent sweep that cdd runs after prox_pv
//                                 (a = the state's tau, any vector does; no
//                                 constraint forces); the file that holds
//                                 constrained_dynamics_derivatives holds it too
//   <case>/idd/pinocchio          pinocchio::computeRNEADerivatives(model, data, q,
//                                 v, a), the same inputs, where CMake found
//                                 Pinocchio: Carpentier and Mansard's derivatives
//                                 in the world frame, which also fill M's upper
//                                 triangle (the pair measures the tangent sweep
//                                 against them; docs/benchmarks.md, "The tangent
//                                 sweep against Pinocchio's RNEA derivatives")
//   <case>/idd/generic_body       the generic twins of idd, the same inputs:
//   <case>/idd/generic_world      inverseDynamicsDerivatives (the body-frame
//                                 sweep) and inverseDynamicsDerivativesWorld (the
//                                 world-frame form, which allocates its per-call
//                                 buffers), both with the constraint rows; their
//                                 agreement is tests/algorithms/test_derivatives.cpp's
//
// mu = 1e4, K = 3 (the suite's, bench/common.hpp). States: 1000 per case from
// proxgen::randomState with seed 1, as bench_joint_space.cpp draws them, drawn
// and converted to the generated Scalar before anything is timed and cycled in
// the timed loop. Before any timing each variant is checked against the generic
// twin, constrainedDynamicsDerivatives (algorithms/derivatives.hpp) at the same
// mu and K, on the first kChecked states (the tolerances are argued at each
// check below); a failed check of a proxgen variant aborts the run, Pinocchio's
// is measured and printed (see pinocchioCheck) and carried as counters.
//
//   proxgen_bench_derivatives [Google Benchmark flags]
//   proxgen_bench_derivatives --count CASE/VARIANT N      (e.g. iiwa_h3/cdd/generated)
// --count sets up only that case and variant (its check included) and makes N
// calls of its body, for instructions per call under callgrind
// (bench/count_calls.py --derivatives): everything but the N calls is the same
// for every N. Exit code 3: no such benchmark in this build.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "algorithms/data.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea_derivatives_world.hpp"
#include "bench_pinocchio.hpp"
#include "bodies.hpp"
#include "cases/cases.hpp"
#include "derivative_solvers.hpp"
#include "model/error.hpp"
#include "model/state.hpp"
#include "numerics.hpp"  // tests/numerics.hpp: test::integrate, q (+) dq
#include "verify/compare.hpp"

namespace {

using proxgen::bench::bodies;

using proxgen::MatX;
using proxgen::VecX;
using proxgen::bench::ConstrainedDerivatives;

constexpr double kMu = 1e4;  // the suite's mu and K (bench/common.hpp)
constexpr int kK = 3;
constexpr int kStates = 1000;
constexpr int kChecked = 3;  // states checked per variant before the timing
// Finite-difference steps, those of tests/algorithms/test_derivatives.cpp: along
// v and tau the K-step iterate is a polynomial of degree <= 2 (no truncation in a
// central difference), so a large step leaves only round-off; along q, 1e-5
// balances the truncation h^2 |f'''| / 6 against the round-off delta |f| / h.
constexpr double kHq = 1e-5, kHv = 1e-2;

struct BenchCase {
  std::string name;
  proxgen::System sys;
  std::vector<proxgen::State> states;
};

std::unique_ptr<BenchCase> loadBenchCase(const std::string& name) {
  auto c = std::make_unique<BenchCase>();
  c->name = name;
  c->sys = proxgen::loadCaseSystem(proxgen::loadCase(PROXGEN_BENCH_CASES_FILE, name));
  std::mt19937 rng(1);
  for (int k = 0; k < kStates; ++k) c->states.push_back(proxgen::randomState(c->sys.model, rng));
  return c;
}

double maxAbs(const MatX& a) { return a.size() ? a.cwiseAbs().maxCoeff() : 0.0; }
using proxgen::verify::relErr;  // max |a - b| / max(1, max |b|)

template <class Scalar>
MatX rowMajor(const std::vector<Scalar>& x, int rows, int cols) {
  MatX out(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) out(r, c) = double(x[std::size_t(r) * cols + c]);
  return out;
}

// The generic twin at state s: constrainedDynamicsDerivatives at (mu, K).
ConstrainedDerivatives generic(const proxgen::System& sys, const proxgen::State& s, int K) {
  proxgen::Data d(sys);
  proxgen::DerivativeData dd(sys);
  proxgen::constrainedDynamicsDerivatives(sys, d, dd, s.q, s.v, s.tau, kMu, K);
  return {dd.qdd, dd.lambda, dd.dqdd_dq, dd.dqdd_dv, dd.dqdd_dtau, dd.dlambda_dq, dd.dlambda_dv, dd.dlambda_dtau};
}

[[noreturn]] void checkFailed(const std::string& what) {
  std::fprintf(stderr, "proxgen_bench_derivatives: %s\n", what.c_str());
  std::exit(2);
}

// One case's generated functions (G: the generated namespace as a type), its
// inputs in the generated Scalar and its outputs, kept for the whole run.
template <class G>
struct Generated {
  using Scalar = typename G::Scalar;
  static constexpr int nq = G::nq, nv = G::nv, nc = G::nc, mc = nc > 0 ? nc : 1;
  const BenchCase& c;
  std::vector<Scalar> q, v, tau;
  typename G::Settings settings;
  std::unique_ptr<typename G::Workspace> w = std::make_unique<typename G::Workspace>();
  // Outputs (row-major blocks, as the generated function writes them).
  std::vector<Scalar> qdd = std::vector<Scalar>(nv), lambda = std::vector<Scalar>(mc);
  std::vector<Scalar> dq = std::vector<Scalar>(nv * nv), dv = dq, dt = dq;
  std::vector<Scalar> lq = std::vector<Scalar>(mc * nv), lv = lq, lt = lq;
  // The differences' work: the perturbed inputs, both solves' answers, one tangent step.
  std::vector<Scalar> qp = std::vector<Scalar>(nq), vp = std::vector<Scalar>(nv), tp = vp;
  std::vector<Scalar> qdd1 = std::vector<Scalar>(nv), qdd2 = qdd1, lambda1 = std::vector<Scalar>(mc), lambda2 = lambda1;
  VecX e = VecX::Zero(nv);

  explicit Generated(const BenchCase& bc) : c(bc) {
    const proxgen::Model& m = c.sys.model;
    if (m.nq != nq || m.nv != nv || c.sys.nc != nc)
      checkFailed("case " + c.name + ": the generated solver's sizes (nq, nv, nc) differ from the model's");
    for (const proxgen::State& s : c.states) {
      for (int i = 0; i < nq; ++i) q.push_back(Scalar(s.q[i]));
      for (int i = 0; i < nv; ++i) v.push_back(Scalar(s.v[i])), tau.push_back(Scalar(s.tau[i]));
    }
    settings.mu = Scalar(kMu);
    settings.iterations = kK;
  }
  const Scalar* at(const std::vector<Scalar>& x, int size, int k) const { return x.data() + std::size_t(k) * size; }

  void idd(int k) {
    G::inverse_dynamics_derivatives(at(q, nq, k), at(v, nv, k), at(tau, nv, k), nullptr, *w, dq.data(), dv.data());
  }

  void cdd(int k) {
    G::constrained_dynamics_derivatives(at(q, nq, k), at(v, nv, k), at(tau, nv, k), settings, *w, qdd.data(),
                                        lambda.data(), dq.data(), dv.data(), dt.data(), lq.data(), lv.data(),
                                        lt.data());
  }

  // q (+) t h e_j into qp (t = +-1): test::integrate on the state's double q, then the Scalar.
  void integrate(int k, int j, double step) {
    e[j] = step;
    const VecX moved = proxgen::test::integrate(c.sys.model, c.states[std::size_t(k)].q, e);
    e[j] = 0.0;
    for (int i = 0; i < nq; ++i) qp[std::size_t(i)] = Scalar(moved[i]);
  }
  // Column j of one input's blocks from the two solves at +h and -h.
  void column(Scalar* dqdd, Scalar* dlambda, int j, double h) {
    const Scalar s = Scalar(1.0 / (2.0 * h));
    for (int i = 0; i < nv; ++i) dqdd[i * nv + j] = (qdd1[std::size_t(i)] - qdd2[std::size_t(i)]) * s;
    for (int i = 0; i < nc; ++i) dlambda[i * nv + j] = (lambda1[std::size_t(i)] - lambda2[std::size_t(i)]) * s;
  }
  void pv(const Scalar* qx, const Scalar* vx, const Scalar* tx, std::vector<Scalar>& a, std::vector<Scalar>& l) {
    G::prox_pv(qx, vx, tx, settings, *w, a.data(), l.data());
  }
  // Central differences of prox_pv at state k with steps hq (q) and hv (v, tau): 6 nv calls.
  void fd(int k, double hq = kHq, double hv = kHv) {
    const Scalar *q0 = at(q, nq, k), *v0 = at(v, nv, k), *t0 = at(tau, nv, k);
    for (int j = 0; j < nv; ++j) {
      integrate(k, j, hq);
      pv(qp.data(), v0, t0, qdd1, lambda1);
      integrate(k, j, -hq);
      pv(qp.data(), v0, t0, qdd2, lambda2);
      column(dq.data(), lq.data(), j, hq);
    }
    std::copy(v0, v0 + nv, vp.begin());
    for (int j = 0; j < nv; ++j) {
      vp[std::size_t(j)] = v0[j] + Scalar(hv);
      pv(q0, vp.data(), t0, qdd1, lambda1);
      vp[std::size_t(j)] = v0[j] - Scalar(hv);
      pv(q0, vp.data(), t0, qdd2, lambda2);
      vp[std::size_t(j)] = v0[j];
      column(dv.data(), lv.data(), j, hv);
    }
    std::copy(t0, t0 + nv, tp.begin());
    for (int j = 0; j < nv; ++j) {
      tp[std::size_t(j)] = t0[j] + Scalar(hv);
      pv(q0, v0, tp.data(), qdd1, lambda1);
      tp[std::size_t(j)] = t0[j] - Scalar(hv);
      pv(q0, v0, tp.data(), qdd2, lambda2);
      tp[std::size_t(j)] = t0[j];
      column(dt.data(), lt.data(), j, hv);
    }
  }
  void integrateOnly(int k) {
    for (int j = 0; j < nv; ++j) {
      integrate(k, j, kHq);
      benchmark::DoNotOptimize(qp.data());
      integrate(k, j, -kHq);
      benchmark::DoNotOptimize(qp.data());
    }
  }
  // The six blocks of the last cdd or fd call, in double.
  ConstrainedDerivatives read() const {
    return {rowMajor(qdd, nv, 1),  rowMajor(lambda, nc, 1), rowMajor(dq, nv, nv), rowMajor(dv, nv, nv),
            rowMajor(dt, nv, nv), rowMajor(lq, nc, nv),    rowMajor(lv, nc, nv), rowMajor(lt, nc, nv)};
  }
};

// The six blocks side by side, for the checks.
const MatX ConstrainedDerivatives::*const kBlocks[6] = {
    &ConstrainedDerivatives::dqdd_dq,    &ConstrainedDerivatives::dqdd_dv,    &ConstrainedDerivatives::dqdd_dtau,
    &ConstrainedDerivatives::dlambda_dq, &ConstrainedDerivatives::dlambda_dv, &ConstrainedDerivatives::dlambda_dtau};
const char* const kBlockNames[6] = {"dqdd_dq", "dqdd_dv", "dqdd_dtau", "dlambda_dq", "dlambda_dv", "dlambda_dtau"};

// cdd/generated against the generic twin with the bounds `proxgen verify` and
// tests/generated/harness_derivatives.cpp apply (verify::compareDerivatives,
// argued in generator/verify/compare.cpp: both sides run the same sweep and the
// same K proximal steps on the tangents with the sums in another order, so each
// entry differs by c n u times the sizes of the terms summed, kappa(M) for the
// solves with M, and the K steps' amplification of their right-hand side's
// error read from G's eigenvalues at the state). Returns the largest error / bound.
template <class G>
double checkCdd(Generated<G>& g) {
  double worst = 0;
  for (int k = 0; k < kChecked; ++k) {
    const proxgen::State& s = g.c.states[std::size_t(k)];
    g.cdd(k);
    const ConstrainedDerivatives r = g.read();
    proxgen::verify::DerivativeAnswer a;
    a.tau = s.tau, a.mu = kMu, a.K = kK;
    a.cQdd = r.qdd, a.cLambda = r.lambda;
    a.cDq = r.dqdd_dq, a.cDv = r.dqdd_dv, a.cDtau = r.dqdd_dtau;
    a.cLq = r.dlambda_dq, a.cLv = r.dlambda_dv, a.cLtau = r.dlambda_dtau;
    proxgen::Data d(g.c.sys);
    const bool isFloat = std::is_same_v<typename G::Scalar, float>;
    const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(g.c.sys, d, s, isFloat);
    for (const proxgen::verify::Compared& x : proxgen::verify::compareDerivatives(g.c.sys, d, cond, s, a)) {
      if (!x.finite || !(x.error <= x.bound))
        checkFailed(g.c.name + "/cdd/generated, state " + std::to_string(k) + ": " + x.what + " differs from the " +
                    "generic twin by " + std::to_string(x.error) + " (bound " + std::to_string(x.bound) + ")");
      worst = std::max(worst, x.error / x.bound);
    }
  }
  return worst;
}

// dtau/dq, dtau/dv at state k (a = its tau, no constraint forces) against the
// generic twin, inverseDynamicsDerivatives, with the bound `proxgen verify`
// applies to the generated inverse_dynamics_derivatives (verify::compareDerivatives:
// the same sweep with the sums in another order, c n u times the sizes of the
// terms summed): one Compared per block, dtau_dq then dtau_dv.
std::vector<proxgen::verify::Compared> compareIdd(const BenchCase& c, int k, const MatX& dq, const MatX& dv) {
  const proxgen::State& s = c.states[std::size_t(k)];
  proxgen::verify::DerivativeAnswer a;
  a.qdd = s.tau, a.lambda = VecX::Zero(c.sys.nc);
  a.dtau_dq = dq, a.dtau_dv = dv;
  proxgen::Data d(c.sys);
  const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(c.sys, d, s, false);
  return proxgen::verify::compareDerivatives(c.sys, d, cond, s, a);
}

// idd/generated against the twin (above); a failure aborts the run.
template <class G>
double checkIdd(Generated<G>& g) {
  double worst = 0;
  for (int k = 0; k < kChecked; ++k) {
    g.idd(k);
    for (const proxgen::verify::Compared& x :
         compareIdd(g.c, k, rowMajor(g.dq, G::nv, G::nv), rowMajor(g.dv, G::nv, G::nv))) {
      if (!x.finite || !(x.error <= x.bound))
        checkFailed(g.c.name + "/idd/generated, state " + std::to_string(k) + ": " + x.what + " differs from the " +
                    "generic twin by " + std::to_string(x.error) + " (bound " + std::to_string(x.bound) + ")");
      worst = std::max(worst, x.error / x.bound);
    }
  }
  return worst;
}

// Central differences of the generic proxPv at (mu, K), the same steps and the
// same test::integrate: what fd/generated_prox_pv computes, in the generic solver.
ConstrainedDerivatives genericDifferences(const proxgen::System& sys, const proxgen::State& s) {
  const proxgen::Model& m = sys.model;
  proxgen::Data d(sys);
  ConstrainedDerivatives out;
  MatX* blocks[3][2] = {{&out.dqdd_dq, &out.dlambda_dq}, {&out.dqdd_dv, &out.dlambda_dv},
                        {&out.dqdd_dtau, &out.dlambda_dtau}};
  for (int in = 0; in < 3; ++in) {
    const double h = in == 0 ? kHq : kHv;
    blocks[in][0]->resize(m.nv, m.nv), blocks[in][1]->resize(sys.nc, m.nv);
    for (int j = 0; j < m.nv; ++j) {
      VecX e = VecX::Zero(m.nv), qdd[2], lambda[2];
      for (int side = 0; side < 2; ++side) {
        e[j] = side == 0 ? h : -h;
        proxgen::State x = s;
        if (in == 0) x.q = proxgen::test::integrate(m, s.q, e);
        if (in == 1) x.v += e;
        if (in == 2) x.tau += e;
        proxgen::proxPv(sys, d, x.q, x.v, x.tau, kMu, kK);
        qdd[side] = d.qdd, lambda[side] = d.lambda;
      }
      blocks[in][0]->col(j) = (qdd[0] - qdd[1]) / (2 * h);
      blocks[in][1]->col(j) = (lambda[0] - lambda[1]) / (2 * h);
    }
  }
  return out;
}

// fd/generated_prox_pv against the generic twin. The differences are not the
// derivative: they carry the truncation h^2 |f'''| / 6 (q only), the round-off
// of the two solves over h, and, along q, the gap between the derivative of the
// K-step iterate and the K proximal steps on the tangents (G moves with q). The
// generic proxPv's differences with the same steps and the same integrate carry
// all three, so the bound is
//   |FD_gen - twin| <= |FD_generic - twin| + |FD_gen - FD_generic|,
// the last being the two solvers' round-off through the difference quotient:
// each solve is within delta max(1, |f|) of the other (delta = verify's dual
// bound of proxPV at the state, c n u (kappa(M) + kappa(G + I/mu)), c = 10, the
// same bound `proxgen verify` holds prox_pv to), so one column differs by at
// most 2 delta max(1, |f|) / (2 h), and 10 times that is allowed (the bound, not
// an estimate, as test_derivatives.cpp's allowance); |f| is the larger of |qdd|
// and |lambda| for both outputs, as qdd's round-off carries the multipliers'
// (test::multiplierRoundoff). Relative to max(1, |twin|).
// Returns the largest error / bound; err gets the largest |FD_gen - twin|
// relative to max(1, |twin|) per block, the differences' own accuracy.
template <class G>
double checkFd(Generated<G>& g, double err[6]) {
  double worst = 0;
  std::fill(err, err + 6, 0.0);
  for (int k = 0; k < kChecked; ++k) {
    const proxgen::State& s = g.c.states[std::size_t(k)];
    const ConstrainedDerivatives twin = generic(g.c.sys, s, kK);
    const ConstrainedDerivatives ref = genericDifferences(g.c.sys, s);
    g.fd(k);
    const ConstrainedDerivatives mine = g.read();
    proxgen::Data d(g.c.sys);
    const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(g.c.sys, d, s, false);
    const double delta = proxgen::verify::boundsAt(cond, kMu).dual;
    const double fq = std::max(1.0, std::max(maxAbs(twin.qdd), maxAbs(twin.lambda)));
    for (int b = 0; b < 6; ++b) {
      const double h = b % 3 == 0 ? kHq : kHv;
      const MatX &a = mine.*kBlocks[b], &r = ref.*kBlocks[b], &t = twin.*kBlocks[b];
      const double scale = std::max(1.0, maxAbs(t));
      const double bound = relErr(r, t) + 10 * delta * fq / h / scale;
      const double e = relErr(a, t);
      if (!a.allFinite() || !(e <= bound))
        checkFailed(g.c.name + "/fd/generated_prox_pv, state " + std::to_string(k) + ": " + kBlockNames[b] +
                    " differs from the generic twin by " + std::to_string(e) + " (bound " + std::to_string(bound) +
                    ")");
      worst = std::max(worst, e / bound);
      err[b] = std::max(err[b], e);
    }
  }
  return worst;
}

#ifdef PROXGEN_BENCH_PINOCCHIO
// cdd/pinocchio against the generic twin. Pinocchio 3.7 runs settings.iter (=
// K here: accuracy 0) proximal steps on the tangents with (G + mu_pin I)^-1
// (constrained-dynamics-derivatives.hxx), i.e. the same K-step quantity as
// proxgen's, so if it is the same computation it meets the bound of
// verify::compareDerivatives (as the generated function, argued above); the
// check measures that and does not assume it: per block the largest relative
// error against the twin at K and against the twin converged (K = 200, the
// test suite's "converged"), and the bound, printed and kept as counters. Only
// a call that is not finite, or stopped before K iterations, aborts the run.
std::vector<std::pair<std::string, double>> pinocchioCheck(const BenchCase& c,
                                                           proxgen::bench::PinocchioConstraintDerivatives& p) {
  double eK[8] = {}, eConv[8] = {}, bound[8] = {};
  for (int k = 0; k < kChecked; ++k) {
    const proxgen::State& s = c.states[std::size_t(k)];
    p.call(k);
    if (p.iterations() != kK)
      checkFailed(c.name + "/cdd/pinocchio: constraintDynamics stopped after " + std::to_string(p.iterations()) +
                  " iterations, not " + std::to_string(kK));
    ConstrainedDerivatives r;
    p.read(r);
    const ConstrainedDerivatives twin = generic(c.sys, s, kK), conv = generic(c.sys, s, 200);
    proxgen::verify::DerivativeAnswer a;
    a.tau = s.tau, a.mu = kMu, a.K = kK;
    a.cQdd = r.qdd, a.cLambda = r.lambda;
    a.cDq = r.dqdd_dq, a.cDv = r.dqdd_dv, a.cDtau = r.dqdd_dtau;
    a.cLq = r.dlambda_dq, a.cLv = r.dlambda_dv, a.cLtau = r.dlambda_dtau;
    proxgen::Data d(c.sys);
    const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(c.sys, d, s, false);
    const std::vector<proxgen::verify::Compared> cmp = proxgen::verify::compareDerivatives(c.sys, d, cond, s, a);
    // compareDerivatives' order: qdd, lambda, then the six blocks as kBlocks.
    for (std::size_t b = 0; b < 8 && b < cmp.size(); ++b) {
      if (!cmp[b].finite) checkFailed(c.name + "/cdd/pinocchio: " + cmp[b].what + " is not finite");
      const MatX x = b == 0 ? MatX(r.qdd) : b == 1 ? MatX(r.lambda) : r.*kBlocks[b - 2];
      const MatX y = b == 0 ? MatX(conv.qdd) : b == 1 ? MatX(conv.lambda) : conv.*kBlocks[b - 2];
      eK[b] = std::max(eK[b], cmp[b].error);
      eConv[b] = std::max(eConv[b], relErr(x, y));
      bound[b] = std::max(bound[b], cmp[b].bound);
    }
  }
  const char* names[8] = {"qdd", "lambda", "dqdd_dq", "dqdd_dv", "dqdd_dtau", "dlambda_dq", "dlambda_dv", "dlambda_dtau"};
  std::vector<std::pair<std::string, double>> counters;
  double worst = 0;
  for (int b = 0; b < 8; ++b) {
    std::fprintf(stderr, "%s/cdd/pinocchio %-12s vs generic K=%d: %.3g (bound %.3g%s), vs converged: %.3g\n",
                 c.name.c_str(), names[b], kK, eK[b], bound[b], eK[b] <= bound[b] ? "" : ", EXCEEDED", eConv[b]);
    worst = std::max(worst, eK[b] / bound[b]);
    if (b >= 2) counters.push_back({std::string("gapK_") + names[b], eK[b]});
  }
  counters.push_back({"check_ratio", worst});
  return counters;
}

// idd/pinocchio against the same twin and bound as idd/generated: measured,
// printed and carried as counters (Pinocchio's tangent convention is the one
// proxgen's derivatives use, so the blocks are compared as they are); only a
// result that is not finite aborts the run.
std::vector<std::pair<std::string, double>> pinocchioRneaCheck(const BenchCase& c,
                                                               proxgen::bench::PinocchioRneaDerivatives& p) {
  double worst = 0, e[2] = {}, bound[2] = {};
  for (int k = 0; k < kChecked; ++k) {
    p.call(k);
    MatX dq, dv;
    p.read(dq, dv);
    const std::vector<proxgen::verify::Compared> cmp = compareIdd(c, k, dq, dv);
    for (std::size_t b = 0; b < 2 && b < cmp.size(); ++b) {
      if (!cmp[b].finite) checkFailed(c.name + "/idd/pinocchio: " + cmp[b].what + " is not finite");
      e[b] = std::max(e[b], cmp[b].error);
      bound[b] = std::max(bound[b], cmp[b].bound);
      worst = std::max(worst, cmp[b].error / cmp[b].bound);
    }
  }
  const char* names[2] = {"dtau_dq", "dtau_dv"};
  for (int b = 0; b < 2; ++b)
    std::fprintf(stderr, "%s/idd/pinocchio %-8s vs generic: %.3g (bound %.3g%s)\n", c.name.c_str(), names[b], e[b],
                 bound[b], e[b] <= bound[b] ? "" : ", EXCEEDED");
  return {{"gap_dtau_dq", e[0]}, {"gap_dtau_dv", e[1]}, {"check_ratio", worst}};
}
#endif

// The variants of one case; `want(variant)` says which to set up (all but in --count).
template <class G>
void registerCase(const char* name, const std::function<bool(const std::string&)>& want) {
  static std::vector<std::unique_ptr<BenchCase>> cases;
  cases.push_back(loadBenchCase(name));
  const BenchCase& c = *cases.back();
  const auto g = std::make_shared<Generated<G>>(c);
  const int nv = G::nv, nc = G::nc;
  const std::string base = c.name + "/";
  const std::vector<std::pair<std::string, double>> sizes{{"K", kK}};  // nv, nc: timedBody
  const auto reg = [&](const std::string& variant, std::function<void(int)> call,
                       std::vector<std::pair<std::string, double>> counters) {
    counters.insert(counters.begin(), sizes.begin(), sizes.end());
    bodies().push_back({base + variant, kStates, nv, nc, std::move(call), std::move(counters)});
  };
  if (want("cdd/generated")) {
    const double ratio = checkCdd(*g);
    reg("cdd/generated", [g](int k) {
      g->cdd(k);
      benchmark::DoNotOptimize(g->dq.data());
    }, {{"check_ratio", ratio}});
  }
  if (want("fd/generated_prox_pv")) {
    double err[6];
    const double ratio = checkFd(*g, err);
    std::vector<std::pair<std::string, double>> counters{{"check_ratio", ratio}};
    for (int b = 0; b < 6; ++b) counters.push_back({std::string("fd_err_") + kBlockNames[b], err[b]});
    reg("fd/generated_prox_pv", [g](int k) {
      g->fd(k);
      benchmark::DoNotOptimize(g->dq.data());
    }, counters);
  }
  if (want("fd/integrate_only")) reg("fd/integrate_only", [g](int k) { g->integrateOnly(k); }, {});
  for (const bool world : {false, true}) {  // the generic twins of idd, a = the state's tau
    const std::string variant = world ? "idd/generic_world" : "idd/generic_body";
    if (!want(variant)) continue;
    const auto d = std::make_shared<proxgen::Data>(c.sys);
    const auto dd = std::make_shared<proxgen::DerivativeData>(c.sys);
    reg(variant, [bc = &c, d, dd, world](int k) {
      const proxgen::State& x = bc->states[std::size_t(k)];
      if (world)
        proxgen::inverseDynamicsDerivativesWorld(bc->sys, *d, *dd, x.q, x.v, x.tau, nullptr);
      else
        proxgen::inverseDynamicsDerivatives(bc->sys, *d, *dd, x.q, x.v, x.tau, nullptr);
      benchmark::DoNotOptimize(dd->dtau_dq.data());
    }, {});
  }
  if (want("idd/generated")) {
    const double ratio = checkIdd(*g);
    reg("idd/generated", [g](int k) {
      g->idd(k);
      benchmark::DoNotOptimize(g->dq.data());
    }, {{"check_ratio", ratio}});
  }
#ifdef PROXGEN_BENCH_PINOCCHIO
  if (want("cdd/pinocchio")) {
    std::shared_ptr<proxgen::bench::PinocchioConstraintDerivatives> p =
        proxgen::bench::makePinocchioConstraintDerivatives(c.name, c.sys, c.states, kMu, kK);
    const auto counters = pinocchioCheck(c, *p);
    reg("cdd/pinocchio", [p](int k) { p->call(k); }, counters);
  }
  if (want("idd/pinocchio")) {
    std::shared_ptr<proxgen::bench::PinocchioRneaDerivatives> p =
        proxgen::bench::makePinocchioRneaDerivatives(c.name, c.sys, c.states);
    const auto counters = pinocchioRneaCheck(c, *p);
    reg("idd/pinocchio", [p](int k) { p->call(k); }, counters);
  }
#endif
}

}  // namespace

// One generated namespace's functions as a type, for registerCase.
#define PROXGEN_BENCH_API(CASE, NS)                                                  \
  namespace api_##CASE {                                                             \
  struct G {                                                                         \
    using Scalar = NS::Scalar;                                                       \
    using Workspace = NS::Workspace;                                                 \
    using Settings = NS::Settings;                                                   \
    static constexpr int nq = NS::nq, nv = NS::nv, nc = NS::nc;                      \
    static constexpr auto prox_pv = &NS::prox_pv;                                    \
    static constexpr auto constrained_dynamics_derivatives =                         \
        &NS::constrained_dynamics_derivatives;                                       \
    static constexpr auto inverse_dynamics_derivatives =                             \
        &NS::inverse_dynamics_derivatives;                                           \
  };                                                                                 \
  }
PROXGEN_BENCH_DERIVATIVE_CASES(PROXGEN_BENCH_API)
#undef PROXGEN_BENCH_API

int main(int argc, char** argv) {
  const bool count = argc >= 2 && std::strcmp(argv[1], "--count") == 0;
  if (count && argc != 4) {
    std::fprintf(stderr, "usage: %s --count CASE/VARIANT N\n", argv[0]);
    return 1;
  }
  const std::string what = count ? argv[2] : "";
  const std::string only = what.substr(0, what.find('/'));
  const std::string variant = count && what.find('/') != std::string::npos ? what.substr(what.find('/') + 1) : "";
  const auto want = [&](const std::string& v) { return !count || v == variant; };
  try {
#define PROXGEN_BENCH_REGISTER(CASE, NS) \
  if (only.empty() || only == #CASE) registerCase<api_##CASE::G>(#CASE, want);
    PROXGEN_BENCH_DERIVATIVE_CASES(PROXGEN_BENCH_REGISTER)
#undef PROXGEN_BENCH_REGISTER
  } catch (const proxgen::Error& e) {
    std::fprintf(stderr, "proxgen_bench_derivatives: %s\n", e.what());
    return 2;
  }
  if (count) return proxgen::bench::countBody("proxgen_bench_derivatives", argv[2], std::stol(argv[3]));
  return proxgen::bench::runBodies(argc, argv);
}

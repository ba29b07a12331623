// The generated derivative functions of one solver (docs/derivatives.md)
// against their generic twins in algorithms/derivatives.cpp, on random states,
// in the solver's Scalar (inputs rounded to it, so both sides answer the same
// question).
//
// Compiled into every harness executable (tests/generated/CMakeLists.txt);
// each test exists only when its solver holds the function
// (PROXGEN_SOLVER_HAS_<NAME>, from proxgen_test_solver's FUNCTIONS).
#if defined(PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS_DERIVATIVES) || defined(PROXGEN_SOLVER_HAS_FORWARD_DYNAMICS_DERIVATIVES) || \
    defined(PROXGEN_SOLVER_HAS_CONSTRAINED_DYNAMICS_DERIVATIVES)
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include PROXGEN_SOLVER_HEADER
#include "algorithms/crba.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/rnea.hpp"
#include "harness_lib.hpp"
#include "support.hpp"
#include "verify/compare.hpp"

namespace {

namespace gen = PROXGEN_SOLVER_NAMESPACE;
using proxgen::MatX;
using proxgen::VecX;

constexpr bool kFloat = std::is_same_v<gen::Scalar, float>;
constexpr double kEps = kFloat ? 5.9604644775390625e-08 : 1.1102230246251565e-16;  // unit round-off, 2^-24 / 2^-53
constexpr double kFloor = kFloat ? 64 * kEps : 1e-12;  // verify/compare.cpp's floor
constexpr int kStates = 20;

double rounded(double x) { return kFloat ? double(float(x)) : x; }
VecX roundedVec(VecX x) {
  for (Eigen::Index k = 0; k < x.size(); ++k) x[k] = rounded(x[k]);
  return x;
}
std::vector<gen::Scalar> toScalar(const VecX& x) {
  std::vector<gen::Scalar> out(std::size_t(std::max<Eigen::Index>(x.size(), 1)));
  for (Eigen::Index k = 0; k < x.size(); ++k) out[std::size_t(k)] = gen::Scalar(x[k]);
  return out;
}
MatX rowMajor(const std::vector<gen::Scalar>& x, int rows, int cols) {
  MatX A(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) A(r, c) = double(x[std::size_t(r * cols + c)]);
  return A;
}
double relErr(const MatX& a, const MatX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}
double maxAbs(const MatX& a) { return a.size() ? a.cwiseAbs().maxCoeff() : 0.0; }

gen::Workspace& workspace() {
  static gen::Workspace w;  // hundreds of kB with the derivative tangents: not on the stack
  return w;
}

struct Sample {
  VecX q, v, qdd, lambda, tau;
};

// Random states (support.hpp's randomState: q, v, tau), qdd ~ N(0, 1),
// lambda ~ 10 N(0, 1) (the library's convention, verify.cpp), all rounded to the Scalar.
std::vector<Sample> samples(const proxgen::System& sys, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Sample> out;
  for (int s = 0; s < kStates; ++s) {
    const proxgen::State st = proxgen::test::randomState(sys.model, rng);
    Sample x{roundedVec(st.q), roundedVec(st.v), VecX(sys.model.nv), VecX(sys.nc), roundedVec(st.tau)};
    for (int k = 0; k < sys.model.nv; ++k) x.qdd[k] = rounded(normal(rng));
    for (int k = 0; k < sys.nc; ++k) x.lambda[k] = rounded(10.0 * normal(rng));
    out.push_back(x);
  }
  return out;
}

// The size of the terms the tangent sweep sums (docs/derivatives.md section
// 2), from the generic sweep's own intermediates: every entry of dtau is a
// sum of products whose partial sums are the body force tangents df_i, the
// forces f_i (the carried S_k x* f_i), and, inside df_i = I da + dv x* I v +
// v x* I dv, the products of the inertia with the motion tangents; a transform
// to the parent multiplies a force by at most 1 + |p| (p its translation,
// rotations are orthogonal). The forward error of such a sum is c n u times
// this size, not the size of its result (gravity and Coriolis terms cancel).
double sweepTermSize(const proxgen::System& sys, const proxgen::Data& d, const proxgen::DerivativeData& dd) {
  double T = 0.0;
  for (int i = 1; i < sys.model.numBodies(); ++i) {
    const double lever = 1.0 + d.liMi[std::size_t(i)].p.norm();
    const double I = sys.model.bodies[std::size_t(i)].inertia.matrix().cwiseAbs().maxCoeff();
    const double vi = d.v[std::size_t(i)].cwiseAbs().maxCoeff();
    const double motion = std::max({maxAbs(dd.da_dq[std::size_t(i)]), maxAbs(dd.da_dv[std::size_t(i)]),
                                    dd.a[std::size_t(i)].cwiseAbs().maxCoeff()}) +
                          2.0 * vi * std::max(maxAbs(dd.dv_dq[std::size_t(i)]), maxAbs(dd.dv_dv[std::size_t(i)]));
    T = std::max({T, lever * maxAbs(dd.df_dq[std::size_t(i)]), lever * maxAbs(dd.df_dv[std::size_t(i)]),
                  lever * dd.f[std::size_t(i)].cwiseAbs().maxCoeff(), lever * 6.0 * I * motion});
  }
  return T;
}

class GeneratedDerivatives : public ::testing::Test {
 protected:
  GeneratedDerivatives() : sys_(proxgen::test::loadSolverSystem(PROXGEN_SOLVER_INPUTS)), d_(sys_), dd_(sys_) {}
  proxgen::System sys_;
  proxgen::Data d_;
  proxgen::DerivativeData dd_;
};

#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS_DERIVATIVES
// inverse_dynamics_derivatives against inverseDynamicsDerivatives with and
// without multipliers. Tolerance: both sides run the same sweep with the sums
// in another order and the model's constants in the Scalar (a relative
// perturbation of u, the same order), so each entry differs by at most
// c n u T, T the size of the terms summed (sweepTermSize), c n = 10 (nv + nc)
// as verify/compare.cpp's other bounds; relative to max(1, max |generic|).
// A dropped term of the sweep (the carried S_k x* f_i, a velocity product)
// changes entries by O(T), far above this at every state.
TEST_F(GeneratedDerivatives, InverseDynamicsDerivativesMatchTheGeneric) {
  const int nv = gen::nv;
  const double safety = 10.0 * (nv + gen::nc);
  double worst = 0.0;
  for (const Sample& s : samples(sys_, 20261202)) {
    for (const bool withLambda : {false, true}) {
      if (withLambda && gen::nc == 0) continue;
      std::vector<gen::Scalar> dq(std::size_t(nv * nv), gen::Scalar(-7)), dv(std::size_t(nv * nv), gen::Scalar(-7));
      const std::vector<gen::Scalar> l = toScalar(s.lambda);
      gen::inverse_dynamics_derivatives(toScalar(s.q).data(), toScalar(s.v).data(), toScalar(s.qdd).data(),
                                        withLambda ? l.data() : nullptr, workspace(), dq.data(), dv.data());
      proxgen::inverseDynamicsDerivatives(sys_, d_, dd_, s.q, s.v, s.qdd, withLambda ? &s.lambda : nullptr);
      const double T = sweepTermSize(sys_, d_, dd_);
      const MatX gq = rowMajor(dq, nv, nv), gv = rowMajor(dv, nv, nv);
      ASSERT_TRUE(gq.allFinite() && gv.allFinite());
      const double bq = std::max(kFloor, safety * kEps * T / std::max(1.0, maxAbs(dd_.dtau_dq)));
      const double bv = std::max(kFloor, safety * kEps * T / std::max(1.0, maxAbs(dd_.dtau_dv)));
      EXPECT_LE(relErr(gq, dd_.dtau_dq), bq) << "dtau_dq, lambda " << withLambda;
      EXPECT_LE(relErr(gv, dd_.dtau_dv), bv) << "dtau_dv, lambda " << withLambda;
      worst = std::max({worst, relErr(gq, dd_.dtau_dq) / bq, relErr(gv, dd_.dtau_dv) / bv});
    }
  }
  std::printf("inverse_dynamics_derivatives: largest error %.2g of the bound\n", worst);
}
#endif

#if PROXGEN_SOLVER_HAS_FORWARD_DYNAMICS_DERIVATIVES
// forward_dynamics_derivatives against forwardDynamicsDerivatives. The
// generated side solves with M^-1 from ABA on the unit torques, the generic
// one with ABA for qdd and a Cholesky factor of CRBA's M: each backward stable,
// so (verify/compare.cpp's argument) M^-1 and qdd differ by c n u kappa(M)
// relative to max(1, max |M^-1|) times what they multiply; the products
// -M^-1 dtau add nv terms of size |M^-1| times (|dtau| + its own error c n u T,
// sweepTermSize, at a qdd that differs by c n u kappa |qdd|, which moves
// the sweep's terms by that relative amount). So, relative to
// max(1, max |generic|):
//   qdd:        c n u kappa(M) max(1, |M^-1|) (|tau| + |h| + |g|) nv
//   dqdd_dq/dv: c n u kappa(M) max(1, |M^-1|) (|dtau| + T) nv
//   dqdd_dtau:  c n u kappa(M) (mass_matrix_inverse's bound).
TEST_F(GeneratedDerivatives, ForwardDynamicsDerivativesMatchTheGeneric) {
  const int nv = gen::nv;
  const double safety = 10.0 * (nv + gen::nc);
  double worst = 0.0;
  for (const Sample& s : samples(sys_, 20261203)) {
    const std::size_t n = std::size_t(nv), n2 = std::size_t(nv * nv);
    std::vector<gen::Scalar> qdd(n), dq(n2), dv(n2), dtau(n2);
    gen::forward_dynamics_derivatives(toScalar(s.q).data(), toScalar(s.v).data(), toScalar(s.tau).data(), workspace(),
                                      qdd.data(), dq.data(), dv.data(), dtau.data());
    proxgen::forwardDynamicsDerivatives(sys_, d_, dd_, s.q, s.v, s.tau);
    const double T = sweepTermSize(sys_, d_, dd_);
    const MatX M = proxgen::crba(sys_, d_, s.q);
    const Eigen::SelfAdjointEigenSolver<MatX> eig(M, Eigen::EigenvaluesOnly);
    const double kappa = eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
    const double minv = std::max(1.0, maxAbs(dd_.dqdd_dtau));
    const MatX h = proxgen::nonLinearEffects(sys_, d_, s.q, s.v);
    const MatX g = proxgen::nonLinearEffects(sys_, d_, s.q, d_.zeroV);
    const double rhs = maxAbs(s.tau) + maxAbs(h) + maxAbs(g);
    const auto bound = [&](double size, const MatX& ref) {
      return std::max(kFloor, safety * kEps * kappa * minv * size * nv / std::max(1.0, maxAbs(ref)));
    };
    const MatX gqdd = rowMajor(qdd, nv, 1), gq = rowMajor(dq, nv, nv), gv = rowMajor(dv, nv, nv),
               gt = rowMajor(dtau, nv, nv);
    ASSERT_TRUE(gqdd.allFinite() && gq.allFinite() && gv.allFinite() && gt.allFinite());
    const double b[4] = {bound(rhs, dd_.qdd), bound(maxAbs(dd_.dtau_dq) + T, dd_.dqdd_dq),
                         bound(maxAbs(dd_.dtau_dv) + T, dd_.dqdd_dv), std::max(kFloor, safety * kEps * kappa)};
    const double e[4] = {relErr(gqdd, dd_.qdd), relErr(gq, dd_.dqdd_dq), relErr(gv, dd_.dqdd_dv),
                         relErr(gt, dd_.dqdd_dtau)};
    const char* what[4] = {"qdd", "dqdd_dq", "dqdd_dv", "dqdd_dtau"};
    for (int k = 0; k < 4; ++k) {
      EXPECT_LE(e[k], b[k]) << what[k];
      worst = std::max(worst, e[k] / b[k]);
    }
  }
  std::printf("forward_dynamics_derivatives: largest error %.2g of the bound\n", worst);
}
#endif


#if PROXGEN_SOLVER_HAS_CONSTRAINED_DYNAMICS_DERIVATIVES
// constrained_dynamics_derivatives against constrainedDynamicsDerivatives at
// the Settings' mu and K (both return the K-step iterates on the tangents, so
// they answer the same question also where K has not converged), with the
// bounds `proxgen verify` applies (verify::compareDerivatives, argued in
// verify/compare.cpp: c n u times the sizes of the terms, kappa(M) for the
// solves with M, and the K proximal steps' amplification of a perturbation of
// their right-hand side, read from G's eigenvalues at each state).
void checkConstrainedDerivatives(const proxgen::System& sys, proxgen::Data& d, gen::Workspace& w,
                                 const gen::Settings& settings, const std::vector<Sample>& states, double& worst) {
  const int nv = gen::nv, nc = gen::nc;
  for (const Sample& s : states) {
    const std::size_t n = std::size_t(nv), m = std::size_t(std::max(nc, 1)), n2 = n * n, mn = m * n;
    std::vector<gen::Scalar> qdd(n), lambda(m), xq(n2), xv(n2), xt(n2), lq(mn), lv(mn), lt(mn);
    gen::constrained_dynamics_derivatives(toScalar(s.q).data(), toScalar(s.v).data(), toScalar(s.tau).data(), settings,
                                          w, qdd.data(), lambda.data(), xq.data(), xv.data(), xt.data(), lq.data(),
                                          lv.data(), lt.data());
    proxgen::verify::DerivativeAnswer a;
    a.tau = s.tau;
    a.mu = double(settings.mu);
    a.K = settings.iterations;
    a.cQdd = rowMajor(qdd, nv, 1);
    a.cLambda = rowMajor(lambda, nc, 1);
    a.cDq = rowMajor(xq, nv, nv), a.cDv = rowMajor(xv, nv, nv), a.cDtau = rowMajor(xt, nv, nv);
    a.cLq = rowMajor(lq, nc, nv), a.cLv = rowMajor(lv, nc, nv), a.cLtau = rowMajor(lt, nc, nv);
    proxgen::State st;
    st.q = s.q, st.v = s.v, st.tau = s.tau;
    const proxgen::verify::Conditioning c = proxgen::verify::conditioningAt(sys, d, st, kFloat);
    for (const proxgen::verify::Compared& x : proxgen::verify::compareDerivatives(sys, d, c, st, a)) {
      ASSERT_TRUE(x.finite) << x.what << ", K = " << settings.iterations;
      EXPECT_LE(x.error, x.bound) << x.what << ", K = " << settings.iterations;
      worst = std::max(worst, x.error / x.bound);
    }
  }
}

TEST_F(GeneratedDerivatives, ConstrainedDynamicsDerivativesMatchTheGeneric) {
  const gen::Settings settings;  // the layout's mu and K
  double worst = 0.0;
  checkConstrainedDerivatives(sys_, d_, workspace(), settings, samples(sys_, 20261204), worst);
  std::printf("constrained_dynamics_derivatives: largest error %.2g of the bound\n", worst);
}

// The K steps' operator S_K at K = 0 (no step: the tangents of the motion under
// lambda0's forces, S_0 = 0), 1 (S_1 = (G + I/mu)^-1 alone) and 2 (one symmetric
// step, as every further one), on fewer states: the generated code forms S_K from
// (G + I/mu)^-1 and K - 1 steps, so each K takes another path through it.
TEST_F(GeneratedDerivatives, ConstrainedDynamicsDerivativesMatchTheGenericAtEveryK) {
  std::vector<Sample> states = samples(sys_, 20261207);
  states.resize(std::min<std::size_t>(states.size(), 5));
  for (const int K : {0, 1, 2}) {
    gen::Settings settings;
    settings.iterations = K;
    double worst = 0.0;
    checkConstrainedDerivatives(sys_, d_, workspace(), settings, states, worst);
    std::printf("constrained_dynamics_derivatives at K = %d: largest error %.2g of the bound\n", K, worst);
  }
}
#endif

}  // namespace
#endif

// Derivatives of the dynamics (docs/derivatives.md): inverse dynamics, ABA and
// the converged constrained solution, each against central finite differences
// on the manifold (q (+) dq as in algorithms/derivatives.hpp, through
// test::integrate) on every shared case and the repository's robots, plus the
// closed forms of d qdd / d tau. The differences are of the generic solvers
// themselves (proxPV converged, K = 200), so a term dropped from the analytic
// side (a Coriolis or gravity term, the constraint forces' motion, the drift,
// a Baumgarte term) shows as a difference of the size of that term.
//
// Steps and tolerances (one argument for all the tests below):
//  - v and tau: qdd and lambda are polynomials of degree <= 2 in v and of
//    degree 1 in tau (h is quadratic in v, gamma too, a* linear; the proximal
//    iterate is linear in its right-hand side), so a central difference has no
//    truncation error; a large step h = 1e-2 leaves only the round-off of the
//    two solves, delta |f| / h.
//  - q: truncation h^2 |f'''| / 6 and round-off delta |f| / h. The dynamics
//    depend on q through rotations and lever arms of 0.05 - 1 m, so |f'''| <=
//    ~1e3 |f'| (m^-2 on the shortest links); h = 1e-5 gives truncation
//    <= 2e-8 max(1, |f'|) and round-off delta |f| / 1e-5. Where that a-priori
//    bound fails (near a singular Jacobian), the constrained checks measure
//    the truncation (expectDifferences below).
//  - delta, the relative error of one solve: c n eps kappa (tests/numerics.hpp,
//    the dual bound of proxPV) for the solvers, c n eps for RNEA (a sum).
// The unconstrained checks compare relative to max(1, max|FD|) (there |f| and
// |f'| are of one size); the constrained ones absolutely, with |f| explicit.
#include <algorithm>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "algorithms/aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea_derivatives_world.hpp"
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kEps;
constexpr double kHq = 1e-5, kHv = 1e-2;
constexpr int kConverged = 200;
constexpr double kTruncationQ = 2e-8;  // h^2 |f'''| / 6 / |f| at h = 1e-5 (above)

// Two states per robot; one under the sanitizer (-O0), which reaches every line.
int statesPerSystem() { return test::kUnderSanitizer ? 1 : 2; }

using Named = test::NamedSystem;

// Every shared case, the examples, and the robots whose features the shared
// cases lack: Baumgarte gains (3d: the quadruped stance; 6d: the floating
// arm), rank-deficient rows (two welds on one link; four coplanar contacts,
// 12 rows on 6 dofs), planar joints, a URDF floating joint, prismatic and
// continuous joints.
std::vector<Named> allSystems() {
  std::vector<Named> out = test::sharedAndRepositorySystems();
  const std::string src = test::sourceDir();
  const auto add = [&](const std::string& name, const std::string& urdf, const std::string& layout) {
    out.push_back({name, loadSystem(src + "/" + urdf, src + "/" + layout)});
  };
  add("planar mobile", "tests/data/good/planar_mobile.urdf", "tests/data/good/planar_mobile.yaml");
  add("floating joint", "tests/data/good/floating_joint.urdf", "tests/data/good/floating_joint.yaml");
  const test::TempFile tip(".yaml");
  tip.write("base: fixed\nconstraints:\n  - {name: tip, link: puck_tip, type: 3d, kp: 20, kd: 3, target: {xyz: [0.3, 0.1, 0.5]}}\n");
  out.push_back({"planar mobile tip", loadSystem(src + "/tests/data/good/planar_mobile.urdf", tip.path())});
  add("arm3 prismatic+continuous", "tests/data/good/arm3.urdf", "tests/data/good/arm3_tool.yaml");
  // Under the sanitizer (-O0, instrumented) the finite differences of the
  // Talos and Atlas cases (nv 50 and 84) took minutes per test; they run the
  // same lines as the robots kept (free flyers, 3d and 6d rows, gains), and
  // the Release run checks them all.
  if (test::kUnderSanitizer)
    out.erase(std::remove_if(out.begin(), out.end(), [](const Named& s) { return s.sys.model.nv > 20; }), out.end());
  return out;
}

double maxAbs(const MatX& A) { return A.size() == 0 ? 0.0 : A.cwiseAbs().maxCoeff(); }
// max |A - B| / max(1, max |B|).
double relErr(const MatX& A, const MatX& B) { return A.size() == 0 ? 0.0 : maxAbs(A - B) / std::max(1.0, maxAbs(B)); }

enum class Input { Q, V, Tau };

// Central differences of f(q, v, tau) (a vector) along every direction of
// one input; q moves on the manifold.
template <class F>
MatX differences(const Model& m, const State& x, Input in, F&& f, double stepScale = 1.0) {
  const double h = stepScale * (in == Input::Q ? kHq : kHv);
  MatX out;
  for (int k = 0; k < m.nv; ++k) {
    VecX e = VecX::Zero(m.nv);
    e[k] = h;
    State p = x, n = x;
    if (in == Input::Q) {
      p.q = test::integrate(m, x.q, e);
      n.q = test::integrate(m, x.q, -e);
    } else if (in == Input::V) {
      p.v += e;
      n.v -= e;
    } else {
      p.tau += e;
      n.tau -= e;
    }
    const VecX fp = f(p), fn = f(n);
    if (k == 0) out = MatX::Zero(fp.size(), m.nv);
    out.col(k) = (fp - fn) / (2 * h);
  }
  return out;
}

// The allowance for |analytic - FD| (absolute, per entry): the round-off of
// the two solves' difference, c delta fScale / h (c = 10: the two errors add
// and each is a bound, not an estimate; fScale: the size of f, so delta fScale
// is one solve's absolute error), plus for q the truncation, relative to the
// derivative's size.
double allowance(Input in, double delta, double fScale, const MatX& fd) {
  const double h = in == Input::Q ? kHq : kHv;
  return 10 * delta * std::max(1.0, fScale) / h + (in == Input::Q ? kTruncationQ * std::max(1.0, maxAbs(fd)) : 0.0);
}
double tolerance(Input in, double delta) { return allowance(in, delta, 1.0, MatX()); }

// The constrained checks. Near a singular Jacobian the constrained solution
// varies on a scale of milliradians (lambda ~ 300 N, d lambda / dq ~ 5e4 N on
// the example arm), where the a-priori |f'''| above does not hold, so there
// the truncation is measured as well: D(2h) - D(h) = 3 (h^2 / 6) f''' +
// O(h^4), so |D(2h) - D(h)| bounds the truncation at h three times over (plus
// 1.5 times the round-off); the allowance takes the larger of the two.
template <class F>
void expectDifferences(const std::string& what, const MatX& analytic, const Model& m, const State& x, Input in, F&& f,
                       double delta, double fScale) {
  const MatX fd = differences(m, x, in, f);
  double bound = allowance(in, delta, fScale, fd);
  if (in == Input::Q) bound = std::max(bound, 10 * delta * std::max(1.0, fScale) / kHq + maxAbs(differences(m, x, in, f, 2.0) - fd));
  EXPECT_LE(maxAbs(analytic - fd), bound) << what << " (|FD| " << maxAbs(fd) << ", |f| " << fScale << ", delta " << delta
                                          << ")";
}

// A random state with random accelerations and multipliers: the inputs of
// inverseDynamicsDerivatives (|qdd| <= 5, |lambda| <= 100).
struct RneaInputs {
  State x;
  VecX qdd, lambda;
};
RneaInputs randomRneaInputs(const System& sys, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-5, 5);
  RneaInputs in{test::randomState(sys.model, rng), VecX(sys.model.nv), VecX(sys.nc)};
  for (int k = 0; k < in.qdd.size(); ++k) in.qdd[k] = u(rng);
  for (int k = 0; k < in.lambda.size(); ++k) in.lambda[k] = 20 * u(rng);
  return in;
}

TEST(Derivatives, InverseDynamicsMatchDifferences) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys), fd(sys);
    DerivativeData dd(sys);
    std::mt19937 rng(31);
    for (int st = 0; st < statesPerSystem(); ++st) {
      const RneaInputs in = randomRneaInputs(sys, rng);
      const State& x = in.x;
      const VecX &qdd = in.qdd, &lambda = in.lambda;  // named: the lambda below captures them
      inverseDynamicsDerivatives(sys, d, dd, x.q, x.v, qdd, &lambda);
      const auto tau = [&](const State& y) -> VecX { return inverseDynamics(sys, fd, y.q, y.v, qdd, &lambda); };
      // RNEA is a sum: delta = c n eps (no condition number).
      const double delta = 10 * sys.model.nv * kEps;
      EXPECT_LE(relErr(dd.dtau_dq, differences(sys.model, x, Input::Q, tau)), tolerance(Input::Q, delta)) << s.name;
      EXPECT_LE(relErr(dd.dtau_dv, differences(sys.model, x, Input::V, tau)), tolerance(Input::V, delta)) << s.name;
    }
  }
}

// The world-frame form (algorithms/rnea_derivatives_world.hpp) against the
// body-frame tangent sweep: two derivations of the same exact quantities, so
// they differ by round-off only.
//  - dtau: each entry of either side is a sum of at most 8 N products (the two
//    sides' terms together) of terms no larger than (1 + L)^2 S: S the largest
//    body-frame force or force tangent of the sweep (subtree sums: dd.f,
//    dd.df_dq, dd.df_dv), L the largest distance of a body from the world
//    origin, since the world-frame moments are the body-frame ones moved by at
//    most L and its products of two moved quantities (Ic c, Bc u) by L^2. So
//    |world - body| <= c 8 N eps (1 + L)^2 S, c = 10 for the few roundings inside
//    each term.
//  - the constraint rows: constraintRowTangents on both sides, from body
//    tangents that the world form computes column by column (no sums over the
//    tree) out of world-frame vectors of size up to (1 + L)^2 T (T: the largest
//    tangent of the constrained bodies, or of the twist and acceleration they
//    are products of), moved back; the rows multiply them by the frame's
//    placement (lever 1 + |p_C|), the twist (3d rows) and the gains. So
//    |world - body| <= c 8 eps (1 + L)^2 T (1 + |p_C|) (1 + |v|) (1 + kp + kd).
// relErr divides by max(1, |reference|). A dropped or wrong term (a Coriolis
// product, the gravity shift, the constraint forces' motion) is of the size of
// the derivative itself.
TEST(Derivatives, WorldFrameFormMatchesTheBodyFrameSweep) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys);
    DerivativeData body(sys), world(sys);
    std::mt19937 rng(37);
    for (int st = 0; st < statesPerSystem(); ++st) {
      const auto [x, qdd, lambda] = randomRneaInputs(sys, rng);
      const VecX* const withAndWithout[2] = {nullptr, &lambda};
      for (const VecX* l : withAndWithout) {
        inverseDynamicsDerivatives(sys, d, body, x.q, x.v, qdd, l);
        double S = 0, L = 0, rows = 0;
        for (int b = 1; b < sys.model.numBodies(); ++b) {
          S = std::max({S, maxAbs(body.f[b]), maxAbs(body.df_dq[b]), maxAbs(body.df_dv[b])});
          L = std::max(L, d.oMi[b].p.norm());
        }
        for (const Constraint& c : sys.constraints) {
          if (c.body == 0) continue;
          const int b = c.body;
          const double T = std::max({maxAbs(body.dv_dq[b]), maxAbs(body.dv_dv[b]), maxAbs(body.da_dq[b]),
                                     maxAbs(body.da_dv[b]), maxAbs(body.dg_dq[b]), maxAbs(d.v[b]), maxAbs(body.a[b])});
          rows = std::max(rows, T * (1 + c.placement.p.norm()) * (1 + maxAbs(d.v[b])) * (1 + c.kp + c.kd));
        }
        inverseDynamicsDerivativesWorld(sys, d, world, x.q, x.v, qdd, l);
        const double tauBound = 10 * 8 * sys.model.numBodies() * kEps * (1 + L) * (1 + L) * S;
        const double rowBound = 10 * 8 * kEps * (1 + L) * (1 + L) * rows;
        const std::pair<const char*, MatX DerivativeData::*> outputs[] = {
            {"dtau_dq", &DerivativeData::dtau_dq},     {"dtau_dv", &DerivativeData::dtau_dv},
            {"J", &DerivativeData::J},                 {"dalpha_dq", &DerivativeData::dalpha_dq},
            {"dalpha_dv", &DerivativeData::dalpha_dv}, {"dastar_dq", &DerivativeData::dastar_dq},
            {"dastar_dv", &DerivativeData::dastar_dv}};
        for (const auto& [name, member] : outputs) {
          const MatX &w = world.*member, &b = body.*member;
          const double bound = member == &DerivativeData::dtau_dq || member == &DerivativeData::dtau_dv ? tauBound : rowBound;
          EXPECT_LE(relErr(w, b), bound / std::max(1.0, maxAbs(b))) << s.name << (l ? ", with lambda: " : ": ") << name;
        }
      }
    }
  }
}

TEST(Derivatives, ForwardDynamicsMatchDifferencesAndDqddDtauIsMinv) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys), fd(sys);
    DerivativeData dd(sys);
    std::mt19937 rng(32);
    for (int st = 0; st < statesPerSystem(); ++st) {
      const State x = test::randomState(sys.model, rng);
      forwardDynamicsDerivatives(sys, d, dd, x.q, x.v, x.tau);
      const MatX M = crba(sys, fd, x.q);
      // ABA is elimination on M: delta = c n eps kappa_s(M).
      const double delta = 10 * sys.model.nv * kEps * test::scaledCondition(M);
      const auto qdd = [&](const State& y) -> VecX { return aba(sys, fd, y.q, y.v, y.tau); };
      EXPECT_LE(relErr(dd.qdd, qdd(x)), delta) << s.name;
      EXPECT_LE(relErr(dd.dqdd_dq, differences(sys.model, x, Input::Q, qdd)), tolerance(Input::Q, delta)) << s.name;
      EXPECT_LE(relErr(dd.dqdd_dv, differences(sys.model, x, Input::V, qdd)), tolerance(Input::V, delta)) << s.name;
      EXPECT_LE(relErr(dd.dqdd_dtau, differences(sys.model, x, Input::Tau, qdd)), tolerance(Input::Tau, delta)) << s.name;
      // The identity: dqdd/dtau = M^-1, here against a dense inverse of CRBA's M
      // (two solves with M: relative error c n eps kappa_s(M) each).
      EXPECT_LE(relErr(dd.dqdd_dtau, M.inverse()), 2 * delta) << s.name;
    }
  }
}

// The orthogonal projector onto range(J) (= range(G)), by a complete
// orthogonal decomposition with the rank rule of denseExact: the part of the
// multipliers the proximal limit determines (docs/derivatives.md §3).
MatX rangeProjector(const MatX& J) {
  Eigen::CompleteOrthogonalDecomposition<MatX> cod(J.rows(), J.cols());
  cod.setThreshold(double(std::max(J.rows(), J.cols())) * kEps);
  cod.compute(J);
  const MatX Q = cod.householderQ();
  return Q.leftCols(cod.rank()) * Q.leftCols(cod.rank()).transpose();
}

// The constrained solution's derivatives against differences of converged
// proxPV solves (K = 200, the System's mu). Where J is rank-deficient the
// multipliers are compared on range(J): along null(J^T) the iterate carries
// round-off (and, for inconsistent rows, K mu y) that no limit determines.
// One solve's error (absolute): delta_s |f| with delta_s the dual bound of
// tests/numerics.hpp, plus for qdd the multipliers' round-off
// (test::multiplierRoundoff) and for the projected lambda the leak of the
// null part through the projector, c nc eps |lambda|.
void checkConstrained(const std::string& at, const System& sys, const State& x, double mu) {
  Data d(sys), fd(sys);
  DerivativeData dd(sys);
  constrainedDynamicsDerivatives(sys, d, dd, x.q, x.v, x.tau, mu, kConverged);
  const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
  const double dual = test::roundoffBounds(p, mu).dual;
  const MatX P = rangeProjector(p.J);
  const double qddScale = std::max(1.0, maxAbs(dd.qdd));
  const double deltaQdd = dual + test::multiplierRoundoff(p, dd.lambda) / qddScale;
  const double lambdaScale = std::max(1.0, maxAbs(MatX(P * dd.lambda)));
  const double deltaLambda = dual + 10 * sys.nc * kEps * maxAbs(dd.lambda) / lambdaScale;
  const auto qdd = [&](const State& y) -> VecX {
    proxPv(sys, fd, y.q, y.v, y.tau, mu, kConverged);
    return fd.qdd;
  };
  const auto lambda = [&](const State& y) -> VecX {
    proxPv(sys, fd, y.q, y.v, y.tau, mu, kConverged);
    return P * fd.lambda;
  };
  const Model& m = sys.model;
  expectDifferences(at + " dqdd_dq", dd.dqdd_dq, m, x, Input::Q, qdd, deltaQdd, qddScale);
  expectDifferences(at + " dqdd_dv", dd.dqdd_dv, m, x, Input::V, qdd, deltaQdd, qddScale);
  expectDifferences(at + " dqdd_dtau", dd.dqdd_dtau, m, x, Input::Tau, qdd, deltaQdd, qddScale);
  if (sys.nc == 0) return;
  expectDifferences(at + " P dlambda_dq", P * dd.dlambda_dq, m, x, Input::Q, lambda, deltaLambda, lambdaScale);
  expectDifferences(at + " P dlambda_dv", P * dd.dlambda_dv, m, x, Input::V, lambda, deltaLambda, lambdaScale);
  expectDifferences(at + " P dlambda_dtau", P * dd.dlambda_dtau, m, x, Input::Tau, lambda, deltaLambda, lambdaScale);
}

TEST(Derivatives, ConstrainedDynamicsMatchDifferencesOfConvergedSolves) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    // Rows on two bodies (the pole's weld and the puck's point) whose
    // redundancy turns with q: not covered (docs/derivatives.md §3); the same
    // robot with the point alone is, through both planar joints.
    if (s.name == "planar mobile") continue;
    std::mt19937 rng(33);
    for (int st = 0; st < statesPerSystem(); ++st)
      checkConstrained(s.name + " state " + std::to_string(st), s.sys, test::randomState(s.sys.model, rng), s.sys.mu);
  }
}

// d qdd / d tau and d lambda / d tau in closed form. The proximal iteration
// on the tau tangents, (G + I/mu) L+ = J M^-1 + L/mu from L = 0, converges to
// the minimum-norm solution of G L = J M^-1, L = G^+ J M^-1 (its right-hand
// side is in range(G) = range(J)), so the limit is
//   d qdd / d tau = M^-1 - M^-1 J^T G^+ J M^-1,   d lambda / d tau = G^+ J M^-1,
// independent of mu. The damped M^-1 - M^-1 J^T (G + I/mu)^-1 J M^-1 is the
// first iterate only; it differs from the limit by M^-1 J^T ((G + I/mu)^-1 -
// G^+) J M^-1 ~ 1 / (mu g) relative, which the check tells apart wherever
// that is above the round-off.
TEST(Derivatives, ConstrainedDqddDtauIsTheProximalLimitNotTheDampedForm) {
  PROXGEN_REQUIRE_MODELS();
  int distinguished = 0;
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    if (sys.nc == 0) continue;
    Data d(sys);
    DerivativeData dd(sys);
    std::mt19937 rng(34);
    const State x = test::randomState(sys.model, rng);
    constrainedDynamicsDerivatives(sys, d, dd, x.q, x.v, x.tau, sys.mu, kConverged);
    const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
    const MatX Minv = p.M.inverse();
    const MatX G = p.J * Minv * p.J.transpose();
    Eigen::CompleteOrthogonalDecomposition<MatX> cod(G.rows(), G.cols());
    cod.setThreshold(double(G.rows()) * kEps);  // the rank rule of denseExact
    cod.compute(G);
    const MatX Gplus = cod.pseudoInverse();
    const MatX limit = Minv - Minv * p.J.transpose() * Gplus * p.J * Minv;
    const MatX damped =
        Minv - Minv * p.J.transpose() * (G + MatX::Identity(sys.nc, sys.nc) / sys.mu).inverse() * p.J * Minv;
    // Both sides chain solves with M and with G (on its range): relative error
    // c n eps (kappa_s(M) + kappa_s(G)), the dual bound, on the scale of M^-1.
    const double bound = test::roundoffBounds(p, sys.mu).dual * std::max(1.0, maxAbs(Minv));
    EXPECT_LE(maxAbs(dd.dqdd_dtau - limit), bound) << s.name;
    const MatX P = rangeProjector(p.J);
    EXPECT_LE(maxAbs(P * dd.dlambda_dtau - Gplus * p.J * Minv), bound * std::max(1.0, maxAbs(Gplus))) << s.name;
    if (maxAbs(damped - limit) > 100 * bound) {
      EXPECT_GT(maxAbs(dd.dqdd_dtau - damped), 10 * bound) << s.name;
      ++distinguished;
    }
  }
  EXPECT_GT(distinguished, 0);  // the two forms were told apart somewhere
}

// A singular configuration: the iiwa straight up (q = 0) with its hand in
// point contact, where the vertical row of J vanishes (rank 2 of 3). At v = 0
// that row is consistent (0 = 0): the proximal limit leaves it without force,
// and its tangent too, so qdd and the multipliers on range(J) are what the
// differences of converged solves give, through the same check as above.
TEST(Derivatives, SingularConfigurationGivesTheProximalLimit) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    if (c.name != "iiwa_h3") continue;
    const System sys = loadCaseSystem(c);
    State x{sys.model.neutral(), VecX::Zero(sys.model.nv), VecX::Zero(sys.model.nv)};
    std::mt19937 rng(35);
    std::uniform_real_distribution<double> u(-5, 5);
    for (int k = 0; k < sys.model.nv; ++k) x.tau[k] = u(rng);
    const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
    const Eigen::JacobiSVD<MatX> svd(p.J);
    ASSERT_LT(svd.singularValues()[2], 1e-12 * svd.singularValues()[0]) << "not a singular configuration";
    checkConstrained("iiwa_h3 stretched", sys, x, sys.mu);
    // And the unconstrained ones, where nothing is singular (M > 0).
    Data d(sys), fd(sys);
    DerivativeData dd(sys);
    forwardDynamicsDerivatives(sys, d, dd, x.q, x.v, x.tau);
    const double delta = 10 * sys.model.nv * kEps * test::scaledCondition(p.M);
    const auto qdd = [&](const State& y) -> VecX { return aba(sys, fd, y.q, y.v, y.tau); };
    EXPECT_LE(relErr(dd.dqdd_dq, differences(sys.model, x, Input::Q, qdd)), tolerance(Input::Q, delta));
    EXPECT_LE(relErr(dd.dqdd_dv, differences(sys.model, x, Input::V, qdd)), tolerance(Input::V, delta));
    return;
  }
  FAIL() << "no iiwa_h3 in the shared cases";
}

}  // namespace
}  // namespace proxgen

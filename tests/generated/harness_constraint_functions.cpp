// The generated constraint functions (constraint_placements, constraint_jacobian,
// constraint_drift, delassus, delassus_inverse) of one solver: against their
// generic twins (the bounds of verify/compare.cpp, the ones `proxgen verify`
// applies) and against identities on their own outputs that the generic code
// does not enter: J is the derivative of the placements, J qdd + gamma = a*
// at the generated constrainedABA's converged answer, (G + I/mu) Ginv = I,
// G = J M^-1 J^T from the generated J.
//
// Compiled into every harness executable (tests/generated/CMakeLists.txt);
// each test exists only when its solver holds the functions it reads
// (PROXGEN_SOLVER_HAS_<NAME>, from proxgen_test_solver's FUNCTIONS).
#if defined(PROXGEN_SOLVER_HAS_CONSTRAINT_PLACEMENTS) || defined(PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN) || \
    defined(PROXGEN_SOLVER_HAS_CONSTRAINT_DRIFT) || defined(PROXGEN_SOLVER_HAS_DELASSUS) ||                  \
    defined(PROXGEN_SOLVER_HAS_DELASSUS_INVERSE) || defined(PROXGEN_SOLVER_HAS_CONSTRAINT_WRENCHES)
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <iterator>
#include <random>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include PROXGEN_SOLVER_HEADER
#include "algorithms/constraints.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/dense_reference.hpp"
#include "harness_lib.hpp"
#include "numerics.hpp"
#include "support.hpp"
#include "verify/compare.hpp"

namespace {

namespace gen = PROXGEN_SOLVER_NAMESPACE;
using proxgen::MatX;
using proxgen::VecX;

constexpr bool kFloat = std::is_same_v<gen::Scalar, float>;
constexpr int kStates = 20;

std::vector<gen::Scalar> toScalar(const VecX& x) {
  std::vector<gen::Scalar> out(std::size_t(std::max<Eigen::Index>(x.size(), 1)));
  for (Eigen::Index k = 0; k < x.size(); ++k) out[std::size_t(k)] = gen::Scalar(x[k]);
  return out;
}
VecX toDouble(const std::vector<gen::Scalar>& x, int n) {
  VecX out(n);
  for (int k = 0; k < n; ++k) out[k] = double(x[std::size_t(k)]);
  return out;
}
// A row-major n x m array as a matrix.
MatX rowMajor(const VecX& x, int rows, int cols) {
  MatX A(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) A(r, c) = x[r * cols + c];
  return A;
}

gen::Workspace& workspace() {
  static gen::Workspace w;  // tens of kB for the big robots: not on the stack
  return w;
}

// The number of constraints (12 placement values each), set by the fixture.
int gConstraints = 0;

// Every generated constraint function of this solver at (q, v), mu for the
// inverse; `active` (ncons flags) the schedule, null: the default (all).
proxgen::verify::ConstraintAnswer runGenerated(const VecX& qIn, const VecX& vIn, double mu,
                                               const std::vector<bool>* activeIn = nullptr) {
  proxgen::verify::ConstraintAnswer a;
  a.mu = mu;
  const std::vector<gen::Scalar> q = toScalar(qIn), v = toScalar(vIn);
  const int nc = gen::nc, nv = gen::nv, ncons = gConstraints;
  gen::Workspace& w = workspace();
  bool active[std::size(gen::all_active)];
  for (std::size_t k = 0; k < std::size(active); ++k) active[k] = activeIn ? bool(activeIn->at(k)) : gen::all_active[k];
  static_cast<void>(w), static_cast<void>(nv), static_cast<void>(ncons), static_cast<void>(v), static_cast<void>(nc);
  static_cast<void>(active);
#ifdef PROXGEN_SOLVER_HAS_CONSTRAINT_PLACEMENTS
  std::vector<gen::Scalar> X(std::size_t(12 * std::max(ncons, 1)));
  gen::constraint_placements(q.data(), w, X.data());
  a.X = toDouble(X, 12 * ncons);
#endif
#ifdef PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN
  std::vector<gen::Scalar> J(std::size_t(std::max(nc * nv, 1)));
  gen::constraint_jacobian(q.data(), w, J.data(), active);
  a.J = toDouble(J, nc * nv);
#endif
#ifdef PROXGEN_SOLVER_HAS_CONSTRAINT_DRIFT
  std::vector<gen::Scalar> gamma(std::size_t(std::max(nc, 1)));
  gen::constraint_drift(q.data(), v.data(), w, gamma.data(), active);
  a.gamma = toDouble(gamma, nc);
#endif
#ifdef PROXGEN_SOLVER_HAS_DELASSUS
  std::vector<gen::Scalar> G(std::size_t(std::max(nc * nc, 1)));
  gen::delassus(q.data(), w, G.data(), active);
  a.G = toDouble(G, nc * nc);
#endif
#ifdef PROXGEN_SOLVER_HAS_DELASSUS_INVERSE
  std::vector<gen::Scalar> Ginv(std::size_t(std::max(nc * nc, 1)));
  gen::Settings s;
  s.mu = gen::Scalar(mu);
  for (std::size_t k = 0; k < std::size(active); ++k) s.active[k] = active[k];
  gen::delassus_inverse(q.data(), s, w, Ginv.data());
  a.Ginv = toDouble(Ginv, nc * nc);
#endif
#ifdef PROXGEN_SOLVER_HAS_CONSTRAINT_WRENCHES
  // Multipliers of the size a solver returns (tens of newtons), distinct per
  // row and state, rounded to the Scalar as the generated function sees them.
  VecX lambdaIn(nc);
  for (int k = 0; k < nc; ++k) lambdaIn[k] = double(gen::Scalar(20.0 * std::sin(1.0 + k + 3.0 * qIn[0])));
  const std::vector<gen::Scalar> l = toScalar(lambdaIn);
  std::vector<gen::Scalar> W(std::size_t(6 * std::max(ncons, 1)));
  gen::constraint_wrenches(q.data(), l.data(), w, W.data());
  a.W = toDouble(W, 6 * ncons);
  a.lambda = lambdaIn;
#endif
  return a;
}

class ConstraintFunctions : public ::testing::Test {
 protected:
  void SetUp() override {
    sys_ = proxgen::test::loadSolverSystem(PROXGEN_SOLVER_INPUTS);
    ASSERT_EQ(sys_.nc, gen::nc);
    gConstraints = int(sys_.constraints.size());
  }
  proxgen::State state(std::mt19937& rng) const {
    return proxgen::verify::roundedToScalar(proxgen::test::randomState(sys_.model, rng), kFloat);
  }
  proxgen::System sys_;
};

TEST_F(ConstraintFunctions, MatchTheGenericTwins) {
  proxgen::Data d(sys_), scratch(sys_);
  std::mt19937 rng(20261201);
  std::map<std::string, std::pair<double, double>> worst;  // per function: largest error, error / bound
  int compared = 0;
  for (int n = 0; n < kStates; ++n) {
    const proxgen::State s = state(rng);
    const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(sys_, scratch, s, kFloat);
    for (double mu : {100.0, 1e4}) {
      const auto items = proxgen::verify::compareConstraintFunctions(sys_, d, cond, s, runGenerated(s.q, s.v, mu));
      for (const proxgen::verify::Compared& x : items) {
        EXPECT_TRUE(x.finite) << x.what << ", state " << n;
        EXPECT_LE(x.error, x.bound) << x.what << ", state " << n << ", mu " << mu;
        auto& w = worst[x.what];
        w = {std::max(w.first, x.error), std::max(w.second, x.error / x.bound)};
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 0);
  for (const auto& [what, w] : worst) std::printf("%s: largest relErr %.1e (%.2f of the bound)\n", what.c_str(), w.first, w.second);
}

// The schedule (Settings::active, or the functions' `active` argument; issue
// 18 item 2): for testSchedules(ncons), the rows (and columns of G, Ginv) of
// the inactive constraints are exact zeros, the placements ignore the
// schedule (geometry), and the active rows are the functions of the
// sub-layout of the active constraints: compared with the generic twins on
// activeSubsystem, with the bounds of MatchTheGenericTwins at its conditioning.
TEST_F(ConstraintFunctions, ScheduleIsTheSubLayout) {
  std::mt19937 rng(20261206);
  const int ncons = int(sys_.constraints.size());
  if (ncons == 0) GTEST_SKIP() << "no constraints";
  double worst = 0;
  for (const std::vector<bool>& active : proxgen::test::testSchedules(ncons)) {
    const proxgen::System sub = proxgen::activeSubsystem(sys_, active);
    const std::vector<int> kept = proxgen::activeRows(sys_, active);
    const int m = int(kept.size());
    std::vector<char> on(std::size_t(gen::nc), 0);
    for (int r : kept) on[std::size_t(r)] = 1;
    proxgen::Data d(sub), scratch(sub);
    for (int n = 0; n < 4; ++n) {
      const proxgen::State s = state(rng);
      const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(sub, scratch, s, kFloat);
      for (double mu : {100.0, 1e4}) {
        const proxgen::verify::ConstraintAnswer all = runGenerated(s.q, s.v, mu);
        const proxgen::verify::ConstraintAnswer g = runGenerated(s.q, s.v, mu, &active);
        proxgen::verify::ConstraintAnswer a;
        a.mu = mu;
        EXPECT_EQ(g.X, all.X) << "the placements take no schedule";
        if (g.X.size()) {
          a.X.resize(12 * Eigen::Index(sub.constraints.size()));
          Eigen::Index at = 0;
          for (std::size_t k = 0; k < active.size(); ++k)
            if (active[k]) a.X.segment<12>(12 * at++) = g.X.segment<12>(12 * Eigen::Index(k));
        }
        if (g.J.size()) {
          a.J.resize(Eigen::Index(m) * gen::nv);
          for (int r = 0; r < gen::nc; ++r)
            for (int c = 0; c < gen::nv; ++c)
              if (!on[std::size_t(r)]) {
                EXPECT_EQ(g.J[r * gen::nv + c], 0.0) << "J, inactive row " << r;
              }
          for (int i = 0; i < m; ++i) a.J.segment(Eigen::Index(i) * gen::nv, gen::nv) = g.J.segment(kept[std::size_t(i)] * gen::nv, gen::nv);
        }
        if (g.gamma.size()) {
          a.gamma.resize(m);
          for (int r = 0; r < gen::nc; ++r)
            if (!on[std::size_t(r)]) {
              EXPECT_EQ(g.gamma[r], 0.0) << "gamma, inactive row " << r;
            }
          for (int i = 0; i < m; ++i) a.gamma[i] = g.gamma[kept[std::size_t(i)]];
        }
        for (const auto& [full, out, what] : {std::tuple{&g.G, &a.G, "G"}, std::tuple{&g.Ginv, &a.Ginv, "Ginv"}}) {
          if (!full->size()) continue;
          out->resize(Eigen::Index(m) * m);
          for (int r = 0; r < gen::nc; ++r)
            for (int c = 0; c < gen::nc; ++c)
              if (!on[std::size_t(r)] || !on[std::size_t(c)]) {
                EXPECT_EQ((*full)[r * gen::nc + c], 0.0) << what << ", inactive entry " << r << ", " << c;
              }
          for (int i = 0; i < m; ++i)
            for (int j = 0; j < m; ++j) (*out)[i * m + j] = (*full)[kept[std::size_t(i)] * gen::nc + kept[std::size_t(j)]];
        }
        for (const proxgen::verify::Compared& x : proxgen::verify::compareConstraintFunctions(sub, d, cond, s, a)) {
          EXPECT_TRUE(x.finite) << x.what << ", state " << n;
          EXPECT_LE(x.error, x.bound) << x.what << ", state " << n << ", mu " << mu;
          worst = std::max(worst, x.error / x.bound);
        }
      }
    }
  }
  std::printf("schedules: largest error / bound against the sub-layout's generic twins %.2f\n", worst);
}

#if defined(PROXGEN_SOLVER_HAS_CONSTRAINT_PLACEMENTS) && defined(PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN)
// The generated J against central differences of the generated placements on
// the configuration manifold (q "+" dq: the free flyer through the exponential
// map, tests/numerics.hpp), as tests/algorithms/test_dynamics_library.cpp
// checks the generic pair: the rows of a frame are its twist in its own
// coordinates (3d: the linear rows). Error of the difference: h^2/6 |d^3X| +
// u/h per unit reach, times 10; double h = 1e-5. In float (u = 6e-8) the best
// step is h = 5e-3 (u/h = 1.2e-5, h^2/6 = 4e-6): bound 10 (h^2/6 + u/h) reach
// with the float u, plus the float round-off of J itself (64 u).
TEST_F(ConstraintFunctions, JacobianIsTheDerivativeOfThePlacements) {
  const proxgen::Model& m = sys_.model;
  const double u = kFloat ? 5.9604644775390625e-08 : proxgen::test::kEps;
  const double h = kFloat ? 5e-3 : 1e-5;
  std::mt19937 rng(20261202);
  const auto rot = [](const VecX& X, Eigen::Index k) {
    proxgen::Mat3 R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = X[12 * k + 3 * r + c];
    return R;
  };
  for (int n = 0; n < kStates; ++n) {
    const proxgen::State s = state(rng);
    const proxgen::verify::ConstraintAnswer a0 = runGenerated(s.q, s.v, 100);
    const MatX J = rowMajor(a0.J, gen::nc, gen::nv);
    double reach = 1;
    for (std::size_t k = 0; k < sys_.constraints.size(); ++k)
      reach = std::max(reach, 1 + a0.X.segment<3>(12 * Eigen::Index(k) + 9).norm());
    const double tol = 10 * (h * h / 6 + u / h) * reach + 64 * u * std::max(1.0, J.cwiseAbs().maxCoeff());
    for (int col = 0; col < m.nv; ++col) {
      const VecX e = VecX::Unit(m.nv, col) * h;
      // The perturbed configurations rounded to the solver's Scalar, and the
      // step taken between the rounded points (float: the rounding moves q by u).
      const VecX Xp = runGenerated(proxgen::test::integrate(m, s.q, e), s.v, 100).X;
      const VecX Xm = runGenerated(proxgen::test::integrate(m, s.q, -e), s.v, 100).X;
      for (std::size_t k = 0; k < sys_.constraints.size(); ++k) {
        const proxgen::Constraint& c = sys_.constraints[k];
        const Eigen::Index kk = Eigen::Index(k);
        const proxgen::Mat3 R0 = rot(a0.X, kk);
        const proxgen::Vec3 dp = Xp.segment<3>(12 * kk + 9) - Xm.segment<3>(12 * kk + 9);
        proxgen::Vec6 fd;
        fd << R0.transpose() * dp, proxgen::test::vee(R0.transpose() * (rot(Xp, kk) - rot(Xm, kk)));
        fd /= 2 * h;
        const double err = (fd.head(c.rows()) - J.block(c.row, col, c.rows(), 1)).cwiseAbs().maxCoeff();
        EXPECT_LE(err, tol) << c.name << " column " << col << ", state " << n;
      }
    }
  }
}
#endif

#if defined(PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN) && defined(PROXGEN_SOLVER_HAS_CONSTRAINT_DRIFT)
// constrainedABA at convergence drives the rows to a* (docs/algorithms.md §2)
// up to the least-squares residual of the exact answer (0 for consistent
// rows): with the generated qdd, J and gamma, |J qdd + gamma - a*| must be
// that residual. Tolerance as the generic test's (test_dynamics_library.cpp,
// JacobianAndDriftAreTheRowsTheSolversHold): the iterates settle to 1e-10
// (convergedIterations), plus the dual round-off bound on qdd seen through
// |J|, plus c n u of the sum's terms. Double only: in float the same sum is
// dominated by u kappa, which the comparison with the generic twins covers.
TEST_F(ConstraintFunctions, JacobianAndDriftHoldTheConvergedRowsAtTheirTarget) {
  if (kFloat || sys_.nc == 0) GTEST_SKIP() << "double solvers with constraints only";
  std::mt19937 rng(20261203);
  const double mu = 1e4;
  int checked = 0;
  for (int n = 0; n < kStates; ++n) {
    const proxgen::State s = state(rng);
    const proxgen::DenseProblem p = proxgen::assembleDense(sys_, s.q, s.v, s.tau);
    const int K = proxgen::test::convergedIterations(p, mu, 1e-10);
    if (K <= 0) continue;  // not settled within the cap: not this identity's question
    std::vector<gen::Scalar> q = toScalar(s.q), v = toScalar(s.v), tau = toScalar(s.tau),
                             qdd(static_cast<std::size_t>(gen::nv)), lambda(std::size_t(std::max(gen::nc, 1)));
    gen::Settings st;
    st.mu = gen::Scalar(mu);
    st.iterations = K;
    gen::constrained_aba(q.data(), v.data(), tau.data(), st, workspace(), qdd.data(), lambda.data());
    const VecX a = toDouble(qdd, gen::nv);
    const proxgen::verify::ConstraintAnswer g = runGenerated(s.q, s.v, mu);
    const MatX J = rowMajor(g.J, gen::nc, gen::nv);
    const VecX rows = J * a + g.gamma - p.aStar;
    VecX qddExact, lambdaExact;
    proxgen::denseExact(p, qddExact, lambdaExact);
    const double exactRes = (p.J * qddExact + p.gamma - p.aStar).norm();
    const double scale = (J.cwiseAbs() * a.cwiseAbs()).maxCoeff() + g.gamma.cwiseAbs().maxCoeff() +
                         (p.aStar.size() ? p.aStar.cwiseAbs().maxCoeff() : 0.0) + sys_.model.gravity.norm();
    const double tolQdd = 1e-10 + proxgen::test::roundoffBounds(p, mu).dual;
    const double tol = (J.cwiseAbs() * VecX::Constant(gen::nv, tolQdd * std::max(1.0, a.cwiseAbs().maxCoeff()))).maxCoeff() *
                           std::sqrt(double(gen::nc)) +
                       10.0 * gen::nv * proxgen::test::kEps * std::max(1.0, scale);
    EXPECT_LE(std::abs(rows.norm() - exactRes), tol) << "state " << n << ", K " << K;
    ++checked;
  }
  EXPECT_GE(2 * checked, kStates) << "too few states converged";
}
#endif

#if defined(PROXGEN_SOLVER_HAS_DELASSUS) && defined(PROXGEN_SOLVER_HAS_DELASSUS_INVERSE)
// (G + I/mu) Ginv = I with both factors generated. Ginv = mu I - mu^2 Omega,
// Omega = J M_mu^-1 J^T, |Omega| <= 1/mu: an error c n u kappa_s(M_mu) |Omega|
// in Omega is c n u kappa_s(M_mu) mu in Ginv, and |G + I/mu| (row sums) times
// that in the residual; G's own error (c n u kappa_s(M) |G|) times |Ginv| <= mu
// adds the same size again (as test_dynamics_library.cpp's bound, with the
// solver's u and a factor 2 for G).
TEST_F(ConstraintFunctions, DelassusInverseInvertsTheGeneratedDelassus) {
  if (sys_.nc == 0) GTEST_SKIP() << "no constraint rows";
  const double u = kFloat ? 5.9604644775390625e-08 : proxgen::test::kEps;
  std::mt19937 rng(20261204);
  for (int n = 0; n < kStates; ++n) {
    const proxgen::State s = state(rng);
    const proxgen::DenseProblem p = proxgen::assembleDense(sys_, s.q, s.v, s.tau);
    for (double mu : {100.0, 1e4}) {
      const proxgen::verify::ConstraintAnswer g = runGenerated(s.q, s.v, mu);
      MatX A = rowMajor(g.G, gen::nc, gen::nc);
      EXPECT_EQ((A - A.transpose()).cwiseAbs().maxCoeff(), 0.0) << "G is exactly symmetric";
      A.diagonal().array() += 1.0 / mu;
      const MatX Ginv = rowMajor(g.Ginv, gen::nc, gen::nc);
      EXPECT_EQ((Ginv - Ginv.transpose()).cwiseAbs().maxCoeff(), 0.0) << "Ginv is exactly symmetric";
      const MatX Mmu = p.M + mu * p.J.transpose() * p.J;
      const double cn = 10.0 * (gen::nv + gen::nc);
      const double errGinv = cn * u * proxgen::test::scaledCondition(Mmu) * mu;
      const double errG = cn * u * proxgen::test::scaledCondition(p.M) * A.cwiseAbs().maxCoeff() * mu;
      const double Amax = A.cwiseAbs().rowwise().sum().maxCoeff();
      const MatX R = A * Ginv - MatX::Identity(gen::nc, gen::nc);
      EXPECT_LE(R.cwiseAbs().maxCoeff(), Amax * errGinv + 2 * errG) << "mu " << mu << ", state " << n;
    }
  }
}
#endif

#if defined(PROXGEN_SOLVER_HAS_DELASSUS) && defined(PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN)
// G = J M^-1 J^T with the generated J (and the generated M^-1 when the solver
// holds mass_matrix_inverse; else M^-1 from CRBA by a Cholesky solve): the
// recursion never forms J, so this ties the two generated functions together.
// Forward error of the solve with M: c n u kappa_s(M) |G|, plus J's own
// round-off (c n u |J|) through the product, |J| |M^-1| |J|.
TEST_F(ConstraintFunctions, DelassusIsJMinvJtOfTheGeneratedJacobian) {
  if (sys_.nc == 0) GTEST_SKIP() << "no constraint rows";
  const double u = kFloat ? 5.9604644775390625e-08 : proxgen::test::kEps;
  proxgen::Data d(sys_);
  std::mt19937 rng(20261205);
  for (int n = 0; n < kStates; ++n) {
    const proxgen::State s = state(rng);
    const proxgen::verify::ConstraintAnswer g = runGenerated(s.q, s.v, 100);
    const MatX J = rowMajor(g.J, gen::nc, gen::nv);
#ifdef PROXGEN_SOLVER_HAS_MASS_MATRIX_INVERSE
    std::vector<gen::Scalar> q = toScalar(s.q), Minv(std::size_t(gen::nv * gen::nv));
    gen::mass_matrix_inverse(q.data(), workspace(), Minv.data());
    const MatX MinvM = rowMajor(toDouble(Minv, gen::nv * gen::nv), gen::nv, gen::nv);
#else
    proxgen::crba(sys_, d, s.q);
    const MatX MinvM = d.M.llt().solve(MatX::Identity(gen::nv, gen::nv));
#endif
    proxgen::crba(sys_, d, s.q);
    const MatX ref = J * MinvM * J.transpose();
    const MatX G = rowMajor(g.G, gen::nc, gen::nc);
    const double cn = 10.0 * (gen::nv + gen::nc);
    const double tol = cn * u *
                       (proxgen::test::scaledCondition(d.M) * ref.cwiseAbs().maxCoeff() +
                        2 * (J.cwiseAbs() * MinvM.cwiseAbs() * J.cwiseAbs().transpose()).maxCoeff());
    EXPECT_LE((G - ref).cwiseAbs().maxCoeff(), tol) << "state " << n;
  }
}
#endif

}  // namespace
#endif

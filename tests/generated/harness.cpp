// One generated solver against the generic solvers it was generated from (the
// checks and their tolerances: harness_lib.cpp, compiled once for all solvers).
//
// Built once per solver by tests/generated/CMakeLists.txt, with
//   PROXGEN_SOLVER_HEADER     "name.hpp"
//   PROXGEN_SOLVER_NAMESPACE  name
//   PROXGEN_SOLVER_CASE       "case" of the shared cases.yaml, or
//   PROXGEN_SOLVER_URDF, PROXGEN_SOLVER_LAYOUT   the inputs it was generated from,
//   PROXGEN_SOLVER_HAS_<FUNCTION>=1  for each function it holds (CONSTRAINED_ABA, MASS_MATRIX, ...).
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include PROXGEN_SOLVER_HEADER
#include "harness_lib.hpp"
#include "model/state.hpp"
#include "support.hpp"
#include "proxgen/runtime.hpp"

namespace {

namespace gen = PROXGEN_SOLVER_NAMESPACE;
using proxgen::VecX;
using proxgen::test::SolverUnderTest;

#if PROXGEN_SOLVER_HAS_CONSTRAINED_ABA && PROXGEN_SOLVER_HAS_PROX_PV
// The generated solver on one state, results in double; lambda0 (nc values)
// or null is Settings::lambda0. Returns residual(w).
// active (ncons flags) or null is Settings::active (null: the default, all true).
double runGeneratedScheduled(SolverUnderTest::Algorithm algorithm, const VecX& qIn, const VecX& vIn, const VecX& tauIn,
                             double mu, int K, const VecX* lambda0In, const std::vector<bool>* active, VecX& qdd,
                             VecX& lambda) {
  std::vector<gen::Scalar> q(gen::nq), v(gen::nv), tau(gen::nv), a(gen::nv), l(std::size_t(std::max(gen::nc, 1))),
      l0(std::size_t(std::max(gen::nc, 1)));
  for (int k = 0; k < gen::nq; ++k) q[std::size_t(k)] = gen::Scalar(qIn[k]);
  for (int k = 0; k < gen::nv; ++k) {
    v[std::size_t(k)] = gen::Scalar(vIn[k]);
    tau[std::size_t(k)] = gen::Scalar(tauIn[k]);
  }
  gen::Settings settings;
  settings.mu = gen::Scalar(mu);
  settings.iterations = K;
  if (lambda0In) {
    for (int k = 0; k < gen::nc; ++k) l0[std::size_t(k)] = gen::Scalar((*lambda0In)[k]);
    settings.lambda0 = l0.data();
  }
  if (active)
    for (int k = 0; k < gen::ncons; ++k) settings.active[k] = active->at(std::size_t(k));
  static gen::Workspace w;  // tens of kB for the big robots: not on the stack
  const auto solve = algorithm == SolverUnderTest::kConstrainedAba ? gen::constrained_aba : gen::prox_pv;
  solve(q.data(), v.data(), tau.data(), settings, w, a.data(), l.data());
  qdd.resize(gen::nv);
  lambda.resize(gen::nc);
  for (int k = 0; k < gen::nv; ++k) qdd[k] = double(a[std::size_t(k)]);
  for (int k = 0; k < gen::nc; ++k) lambda[k] = double(l[std::size_t(k)]);
  return double(gen::residual(w));
}

double runGeneratedFrom(SolverUnderTest::Algorithm algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu,
                        int K, const VecX* lambda0, VecX& qdd, VecX& lambda) {
  return runGeneratedScheduled(algorithm, q, v, tau, mu, K, lambda0, nullptr, qdd, lambda);
}

void runGenerated(SolverUnderTest::Algorithm algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu,
                  int K, VecX& qdd, VecX& lambda) {
  runGeneratedFrom(algorithm, q, v, tau, mu, K, nullptr, qdd, lambda);
}

SolverUnderTest solverUnderTest() {
  SolverUnderTest solver;
  solver.nq = gen::nq;
  solver.nv = gen::nv;
  solver.nc = gen::nc;
  solver.isFloat = std::is_same_v<gen::Scalar, float>;
  solver.run = runGenerated;
  solver.runFrom = runGeneratedFrom;
  solver.runScheduled = runGeneratedScheduled;
  return solver;
}
#endif

[[maybe_unused]] std::vector<gen::Scalar> toScalar(const VecX& x) {
  std::vector<gen::Scalar> out(std::size_t(std::max<Eigen::Index>(x.size(), 1)));
  for (int k = 0; k < x.size(); ++k) out[std::size_t(k)] = gen::Scalar(x[k]);
  return out;
}

[[maybe_unused]] VecX toDouble(const std::vector<gen::Scalar>& x, int n) {
  VecX out(n);
  for (int k = 0; k < n; ++k) out[k] = double(x[std::size_t(k)]);
  return out;
}

[[maybe_unused]] proxgen::MatX squareToDouble(const std::vector<gen::Scalar>& x) {
  proxgen::MatX out(gen::nv, gen::nv);
  for (int r = 0; r < gen::nv; ++r)
    for (int c = 0; c < gen::nv; ++c) out(r, c) = double(x[std::size_t(r * gen::nv + c)]);  // row-major
  return out;
}

[[maybe_unused]] gen::Workspace& workspace() {
  static gen::Workspace w;  // tens of kB for the big robots: not on the stack
  return w;
}

class Generated : public ::testing::Test {
 protected:
  void SetUp() override {
    sys_ = proxgen::test::loadSolverSystem(PROXGEN_SOLVER_INPUTS);
    ASSERT_EQ(sys_.model.nq, gen::nq);
    ASSERT_EQ(sys_.model.nv, gen::nv);
    ASSERT_EQ(sys_.nc, gen::nc);
  }
  proxgen::System sys_;
};

TEST_F(Generated, SettingsDefaultsAreTheLayouts) {
  const gen::Settings s;
  EXPECT_EQ(double(s.mu), double(gen::Scalar(sys_.mu)));
  EXPECT_EQ(s.iterations, sys_.iterations);
}

#if PROXGEN_SOLVER_HAS_CONSTRAINED_ABA && PROXGEN_SOLVER_HAS_PROX_PV
TEST_F(Generated, MatchesTheGenericSolvers) {
  proxgen::test::expectMatchesTheGenericSolvers(solverUnderTest(), sys_);
}

// ---- The controller API of issue 18 (items 1, 3, 4): names and slots, the
// version, the quaternion's scale, the warm start, the residual.
TEST_F(Generated, NamesAndSlotsAreTheModels) {
  const proxgen::Model& m = sys_.model;
  const int joints = m.numBodies() - 1;
  ASSERT_EQ(int(std::size(gen::joint_names)), std::max(joints, 1));  // one placeholder when empty
  for (int k = 0; k < joints; ++k) {
    const proxgen::Joint& j = m.bodies[std::size_t(k + 1)].joint;
    EXPECT_EQ(std::string(gen::joint_names[k]), j.name) << "joint " << k;  // byte for byte
    EXPECT_EQ(gen::joint_idx_q[k], j.idx_q) << j.name;
    EXPECT_EQ(gen::joint_idx_v[k], j.idx_v) << j.name;
  }
  ASSERT_EQ(gen::ncons, int(sys_.constraints.size()));
  ASSERT_EQ(int(std::size(gen::constraint_names)), std::max(gen::ncons, 1));
  for (int k = 0; k < gen::ncons; ++k) {
    const proxgen::Constraint& c = sys_.constraints[std::size_t(k)];
    EXPECT_EQ(std::string(gen::constraint_names[k]), c.name) << "constraint " << k;
    EXPECT_EQ(gen::constraint_row[k], c.row) << c.name;
    EXPECT_EQ(gen::constraint_rows[k], c.rows()) << c.name;
  }
}

TEST_F(Generated, VersionIsTheGeneratorsAndTheRuntimes) {
  EXPECT_STREQ(gen::proxgen_version, PROXGEN_VERSION);
  EXPECT_EQ(gen::version_major, proxgen_rt::version_major);
  EXPECT_EQ(gen::version_minor, proxgen_rt::version_minor);
}

TEST_F(Generated, QuaternionScaleIsIgnored) {
  if (!sys_.model.floatingBase) GTEST_SKIP() << "no free flyer";
  proxgen::test::expectQuaternionScaleIsIgnored(solverUnderTest(), sys_);
}

TEST_F(Generated, WarmStartMatchesTheGeneric) {
  proxgen::test::expectWarmStartMatchesTheGeneric(solverUnderTest(), sys_);
}

// The header promises lambda0 is read before lambda is written: the previous
// step's lambda array can be both (README's controller loop). Same operations
// on the same values: the same bits.
TEST_F(Generated, WarmStartMayBeTheLambdaOutput) {
  if (gen::nc == 0) GTEST_SKIP() << "no constraints";
  std::vector<gen::Scalar> q(gen::nq, gen::Scalar(0.1)), v(gen::nv, gen::Scalar(0.2)), tau(gen::nv, gen::Scalar(0.3)),
      qdd(gen::nv), l0(gen::nc), lOut(gen::nc), qddAlias(gen::nv), lAlias(gen::nc);
  if (sys_.model.floatingBase && gen::nq > 6) q[6] = gen::Scalar(1);  // w of a unit quaternion (0.1, 0.1, 0.1, 1) scaled: fine
  for (int k = 0; k < gen::nc; ++k) l0[std::size_t(k)] = lAlias[std::size_t(k)] = gen::Scalar(0.5 + k);
  static gen::Workspace w;
  for (auto solve : {gen::constrained_aba, gen::prox_pv}) {
    gen::Settings s;
    s.lambda0 = l0.data();
    solve(q.data(), v.data(), tau.data(), s, w, qdd.data(), lOut.data());
    for (int k = 0; k < gen::nc; ++k) lAlias[std::size_t(k)] = l0[std::size_t(k)];
    s.lambda0 = lAlias.data();
    solve(q.data(), v.data(), tau.data(), s, w, qddAlias.data(), lAlias.data());
    EXPECT_EQ(qddAlias, qdd);
    EXPECT_EQ(lAlias, lOut);
    EXPECT_NE(lOut, l0);  // the multipliers moved: the comparison can see a clobbered lambda0
  }
}

// Issue 18 item 2: Settings::active, against the generic solvers on the
// sub-layout of the active constraints (harness_lib.cpp).
TEST_F(Generated, ScheduleIsTheSubLayout) {
  proxgen::test::expectScheduleIsTheSubLayout(solverUnderTest(), sys_);
}

TEST_F(Generated, ResidualIsTheConstraintResidual) {
  proxgen::test::expectResidualIsTheConstraintResidual(solverUnderTest(), sys_);
}

#endif

#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS
// inverse_dynamics' schedule (issue 18 item 2): the rows of an inactive
// constraint are never read, so lambda with NaN there gives the bits of lambda
// with 0 there and the default schedule (the same operations on the same
// values; were the schedule ignored, the NaN would reach tau).
TEST_F(Generated, InverseDynamicsIgnoresTheInactiveMultipliers) {
  if (gen::nc == 0) GTEST_SKIP() << "no constraints";
  std::mt19937 rng(20261207);
  const proxgen::State st = proxgen::test::randomState(sys_.model, rng);
  const std::vector<gen::Scalar> q = toScalar(st.q), v = toScalar(st.v), qdd = toScalar(st.tau);
  for (const std::vector<bool>& schedule : proxgen::test::testSchedules(gen::ncons)) {
    bool active[std::size(gen::all_active)] = {};
    std::vector<gen::Scalar> lNan(gen::nc), lZero(gen::nc), tauNan(gen::nv), tauZero(gen::nv);
    for (int k = 0; k < gen::ncons; ++k) {
      active[k] = schedule[std::size_t(k)];
      for (int r = gen::constraint_row[k]; r < gen::constraint_row[k] + gen::constraint_rows[k]; ++r) {
        lNan[std::size_t(r)] = active[k] ? gen::Scalar(0.5 + r) : std::numeric_limits<gen::Scalar>::quiet_NaN();
        lZero[std::size_t(r)] = active[k] ? gen::Scalar(0.5 + r) : gen::Scalar(0);
      }
    }
    gen::inverse_dynamics(q.data(), v.data(), qdd.data(), lNan.data(), workspace(), tauNan.data(), active);
    gen::inverse_dynamics(q.data(), v.data(), qdd.data(), lZero.data(), workspace(), tauZero.data());
    EXPECT_EQ(tauNan, tauZero);
  }
}
#endif

#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS || PROXGEN_SOLVER_HAS_NONLINEAR_EFFECTS || PROXGEN_SOLVER_HAS_MASS_MATRIX || \
    PROXGEN_SOLVER_HAS_MASS_MATRIX_INVERSE
TEST_F(Generated, JointSpaceFunctionsMatchTheGeneric) {
  proxgen::test::LibraryUnderTest lib;
  lib.isFloat = std::is_same_v<gen::Scalar, float>;
  // The outputs start as NaN: an entry the function does not write (mass_matrix
  // and mass_matrix_inverse write theirs piecemeal, the zeros apart) fails the comparison.
  static constexpr gen::Scalar kUnwritten = std::numeric_limits<gen::Scalar>::quiet_NaN();
#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS
  lib.inverseDynamics = [](const VecX& q, const VecX& v, const VecX& qdd, const VecX* lambda, VecX& tau) {
    std::vector<gen::Scalar> out(gen::nv, kUnwritten);
    const std::vector<gen::Scalar> l = lambda ? toScalar(*lambda) : std::vector<gen::Scalar>();
    gen::inverse_dynamics(toScalar(q).data(), toScalar(v).data(), toScalar(qdd).data(), lambda ? l.data() : nullptr,
                          workspace(), out.data());
    tau = toDouble(out, gen::nv);
  };
#endif
#if PROXGEN_SOLVER_HAS_NONLINEAR_EFFECTS
  lib.nonlinearEffects = [](const VecX& q, const VecX& v, VecX& h) {
    std::vector<gen::Scalar> out(gen::nv, kUnwritten);
    gen::nonlinear_effects(toScalar(q).data(), toScalar(v).data(), workspace(), out.data());
    h = toDouble(out, gen::nv);
  };
#endif
#if PROXGEN_SOLVER_HAS_MASS_MATRIX
  lib.massMatrix = [](const VecX& q, proxgen::MatX& M) {
    std::vector<gen::Scalar> out(std::size_t(gen::nv * gen::nv), kUnwritten);
    gen::mass_matrix(toScalar(q).data(), workspace(), out.data());
    M = squareToDouble(out);
  };
#endif
#if PROXGEN_SOLVER_HAS_MASS_MATRIX_INVERSE
  lib.massMatrixInverse = [](const VecX& q, proxgen::MatX& Minv) {
    std::vector<gen::Scalar> out(std::size_t(gen::nv * gen::nv), kUnwritten);
    gen::mass_matrix_inverse(toScalar(q).data(), workspace(), out.data());
    Minv = squareToDouble(out);
  };
#endif
#if PROXGEN_SOLVER_HAS_PROX_PV
  SolverUnderTest solver;
  solver.nq = gen::nq;
  solver.nv = gen::nv;
  solver.nc = gen::nc;
  solver.isFloat = lib.isFloat;
  solver.run = [](SolverUnderTest::Algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu, int K, VecX& qdd,
                  VecX& lambda) {
    std::vector<gen::Scalar> a(gen::nv), l(std::size_t(std::max(gen::nc, 1)));
    gen::Settings settings;
    settings.mu = gen::Scalar(mu);
    settings.iterations = K;
    gen::prox_pv(toScalar(q).data(), toScalar(v).data(), toScalar(tau).data(), settings, workspace(), a.data(), l.data());
    qdd = toDouble(a, gen::nv);
    lambda = toDouble(l, gen::nc);
  };
  proxgen::test::expectLibraryMatchesTheGeneric(lib, &solver, sys_);
#else
  proxgen::test::expectLibraryMatchesTheGeneric(lib, nullptr, sys_);
#endif
}
#endif

}  // namespace

// One generated solver against the generic solvers it was generated from (the
// checks and their tolerances: harness_lib.cpp, compiled once for all solvers).
//
// Built once per solver by tests/generated/CMakeLists.txt, with
//   PROXGEN_SOLVER_HEADER     "name.hpp"
//   PROXGEN_SOLVER_NAMESPACE  name
//   PROXGEN_SOLVER_CASE       "case" of the shared cases.yaml, or
//   PROXGEN_SOLVER_URDF, PROXGEN_SOLVER_LAYOUT   the inputs it was generated from.
#include <gtest/gtest.h>

#include <algorithm>
#include <type_traits>
#include <vector>

#include PROXGEN_SOLVER_HEADER
#include "harness_lib.hpp"

namespace {

namespace gen = PROXGEN_SOLVER_NAMESPACE;
using proxgen::VecX;
using proxgen::test::SolverUnderTest;

#ifdef PROXGEN_SOLVER_CASE
#define PROXGEN_SOLVER_INPUTS PROXGEN_SOLVER_CASE, nullptr, nullptr
#else
#define PROXGEN_SOLVER_INPUTS nullptr, PROXGEN_SOLVER_URDF, PROXGEN_SOLVER_LAYOUT
#endif

// The generated solver on one state, results in double.
void runGenerated(SolverUnderTest::Algorithm algorithm, const VecX& qIn, const VecX& vIn, const VecX& tauIn, double mu,
                  int K, VecX& qdd, VecX& lambda) {
  std::vector<gen::Scalar> q(gen::nq), v(gen::nv), tau(gen::nv), a(gen::nv), l(std::size_t(std::max(gen::nc, 1)));
  for (int k = 0; k < gen::nq; ++k) q[std::size_t(k)] = gen::Scalar(qIn[k]);
  for (int k = 0; k < gen::nv; ++k) {
    v[std::size_t(k)] = gen::Scalar(vIn[k]);
    tau[std::size_t(k)] = gen::Scalar(tauIn[k]);
  }
  gen::Settings settings;
  settings.mu = gen::Scalar(mu);
  settings.iterations = K;
  static gen::Workspace w;  // tens of kB for the big robots: not on the stack
  const auto solve = algorithm == SolverUnderTest::kConstrainedAba ? gen::constrained_aba : gen::prox_pv;
  solve(q.data(), v.data(), tau.data(), settings, w, a.data(), l.data());
  qdd.resize(gen::nv);
  lambda.resize(gen::nc);
  for (int k = 0; k < gen::nv; ++k) qdd[k] = double(a[std::size_t(k)]);
  for (int k = 0; k < gen::nc; ++k) lambda[k] = double(l[std::size_t(k)]);
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

TEST_F(Generated, MatchesTheGenericSolvers) {
  SolverUnderTest solver;
  solver.nq = gen::nq;
  solver.nv = gen::nv;
  solver.nc = gen::nc;
  solver.isFloat = std::is_same_v<gen::Scalar, float>;
  solver.run = runGenerated;
  proxgen::test::expectMatchesTheGenericSolvers(solver, sys_);
}

}  // namespace

// "No allocation inside a solve" (docs/design.md, "Tests by stage"): every generic algorithm runs on
// the preallocated Data. This executable is linked with --wrap=malloc/calloc/
// realloc (tests/CMakeLists.txt), so every heap allocation made by proxgen_core's
// code, Eigen's included, passes through the counters below; a solve must leave
// them unchanged.
#include <cstdlib>
#include <new>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "support.hpp"

namespace {
bool g_counting = false;  // set while a solve runs
long g_allocations = 0;
}  // namespace

extern "C" {
void* __real_malloc(std::size_t);
void* __real_calloc(std::size_t, std::size_t);
void* __real_realloc(void*, std::size_t);
void* __wrap_malloc(std::size_t n) {
  if (g_counting) ++g_allocations;
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t s) {
  if (g_counting) ++g_allocations;
  return __real_calloc(n, s);
}
void* __wrap_realloc(void* p, std::size_t n) {
  if (g_counting) ++g_allocations;
  return __real_realloc(p, n);
}
}

void* operator new(std::size_t n) {
  if (g_counting) ++g_allocations;
  if (void* p = __real_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace proxgen {
namespace {

using Solver = void (*)(const System&, Data&, const VecX&, const VecX&, const VecX&, double, int);

long allocationsOf(const System& sys, Data& d, const test::RandomState& s, Solver solve) {
  solve(sys, d, s.q, s.v, s.tau, 1e4, 3);  // warm-up: lazy one-time set-up is allowed
  g_allocations = 0;
  g_counting = true;
  solve(sys, d, s.q, s.v, s.tau, 1e4, 3);
  solve(sys, d, s.q, s.v, s.tau, 100.0, 5);
  g_counting = false;
  return g_allocations;
}

TEST(NoAllocation, CounterWorks) {
  // The check itself can fail: an allocation made while counting is seen.
  g_allocations = 0;
  g_counting = true;
  VecX x = VecX::Zero(50);
  asm volatile("" : : "r"(x.data()) : "memory");  // keep the allocation from being elided
  g_counting = false;
  EXPECT_GT(g_allocations, 0);
}

TEST(NoAllocation, GenericSolversOnEverySharedCase) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys);
    std::mt19937 rng(7);
    const test::RandomState s = test::randomState(sys.model, rng);
    const Solver aba3 = [](const System& y, Data& dd, const VecX& q, const VecX& v, const VecX& t, double, int) {
      aba(y, dd, q, v, t);
    };
    EXPECT_EQ(allocationsOf(sys, d, s, aba3), 0) << c.name << " aba";
    EXPECT_EQ(allocationsOf(sys, d, s, &constrainedAba), 0) << c.name << " constrainedAba";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxPv), 0) << c.name << " proxPv";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxLtl), 0) << c.name << " proxLtl";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxLtls), 0) << c.name << " proxLtls";
  }
}

// Planar joints (from the root and below a moving body) and a free flyer from
// the URDF take their own branches in the elimination: no heap there either.
TEST(NoAllocation, GenericSolversOnMobileBases) {
  const std::string dir = std::string(PROXGEN_TEST_DATA_DIR) + "/good/";
  for (const char* name : {"planar_mobile", "floating_joint"}) {
    const System sys = loadSystem(dir + name + ".urdf", dir + name + ".yaml");
    Data d(sys);
    std::mt19937 rng(7);
    const test::RandomState s = test::randomState(sys.model, rng);
    const Solver aba3 = [](const System& y, Data& dd, const VecX& q, const VecX& v, const VecX& t, double, int) {
      aba(y, dd, q, v, t);
    };
    EXPECT_EQ(allocationsOf(sys, d, s, aba3), 0) << name << " aba";
    EXPECT_EQ(allocationsOf(sys, d, s, &constrainedAba), 0) << name << " constrainedAba";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxPv), 0) << name << " proxPv";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxLtl), 0) << name << " proxLtl";
    EXPECT_EQ(allocationsOf(sys, d, s, &proxLtls), 0) << name << " proxLtls";
  }
}

// The dynamics library (docs/dynamics.md): every function, twice after a warm-up.
TEST(NoAllocation, DynamicsLibraryOnEverySharedCase) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys);
    std::mt19937 rng(8);
    const test::RandomState s = test::randomState(sys.model, rng);
    const VecX lambda = VecX::Ones(sys.nc);
    MatX out(sys.nc, sys.nc);
    const auto all = [&] {
      inverseDynamics(sys, d, s.q, s.v, s.tau, &lambda);
      inverseDynamics(sys, d, s.q, s.v, s.tau, nullptr);
      nonLinearEffects(sys, d, s.q, s.v);
      crba(sys, d, s.q);
      massMatrixInverse(sys, d, s.q);
      constraintPlacements(sys, d, s.q);
      constraintJacobianRows(sys, d, s.q);
      constraintDrift(sys, d, s.q, s.v);
      delassus(sys, d, s.q);
      delassusRecursion(sys, d, s.q, 0.0, out);
      delassusInverse(sys, d, s.q, 1e4);
    };
    all();  // warm-up
    g_allocations = 0;
    g_counting = true;
    all();
    all();
    g_counting = false;
    EXPECT_EQ(g_allocations, 0) << c.name;
  }
}

// The derivatives (docs/derivatives.md) on their preallocated DerivativeData.
TEST(NoAllocation, DerivativesOnEverySharedCase) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys);
    DerivativeData dd(sys);
    std::mt19937 rng(9);
    const test::RandomState s = test::randomState(sys.model, rng);
    const VecX lambda = VecX::Ones(sys.nc);
    for (int f = 0; f < 3; ++f) {
      const auto run = [&] {
        if (f == 0) inverseDynamicsDerivatives(sys, d, dd, s.q, s.v, s.tau, &lambda);
        if (f == 1) forwardDynamicsDerivatives(sys, d, dd, s.q, s.v, s.tau);
        if (f == 2) constrainedDynamicsDerivatives(sys, d, dd, s.q, s.v, s.tau, 1e4, 3);
      };
      run();  // warm-up
      g_allocations = 0;
      g_counting = true;
      run();
      g_counting = false;
      EXPECT_EQ(g_allocations, 0) << c.name << " " << (f == 0 ? "inverse" : f == 1 ? "forward" : "constrained");
    }
  }
}

}  // namespace
}  // namespace proxgen

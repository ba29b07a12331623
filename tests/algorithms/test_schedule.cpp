// The run-time schedule's definition (docs/algorithms.md §4.4): activeSubsystem
// keeps the active constraints in layout order with their rows renumbered, so
// the sub-layout's dense problem is the full one's active rows, exactly (the
// same row computations, only the stacking differs), and the generated
// solvers' flags are checked against the generic solvers on it
// (tests/generated/harness_lib.cpp).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "algorithms/constraints.hpp"
#include "algorithms/dense_reference.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

TEST(Schedule, ActiveSubsystemKeepsTheActiveRowsInLayoutOrder) {
  PROXGEN_REQUIRE_MODELS();
  std::mt19937 rng(20261208);
  int checked = 0;
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    const std::size_t n = sys.constraints.size();
    if (n == 0) continue;
    const test::RandomState s = test::randomState(sys.model, rng);
    const DenseProblem full = assembleDense(sys, s.q, s.v, s.tau);
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<bool> active(n);
      for (std::size_t k = 0; k < n; ++k) active[k] = trial == 0 ? true : trial == 1 ? false : (rng() & 1u) != 0;
      const System sub = activeSubsystem(sys, active);
      const std::vector<int> rows = activeRows(sys, active);
      ASSERT_EQ(sub.nc, int(rows.size())) << c.name;
      std::size_t kept = 0;
      int row = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (!active[k]) continue;
        ASSERT_LT(kept, sub.constraints.size());
        EXPECT_EQ(sub.constraints[kept].name, sys.constraints[k].name) << c.name;
        EXPECT_EQ(sub.constraints[kept].row, row) << c.name;
        row += sub.constraints[kept].rows();
        ++kept;
      }
      EXPECT_EQ(kept, sub.constraints.size());
      const DenseProblem p = assembleDense(sub, s.q, s.v, s.tau);
      EXPECT_EQ(p.M, full.M);
      for (std::size_t r = 0; r < rows.size(); ++r) {
        const Eigen::Index i = Eigen::Index(r);
        EXPECT_EQ(p.J.row(i), full.J.row(rows[r])) << c.name << " row " << rows[r];
        EXPECT_EQ(p.gamma[i], full.gamma[rows[r]]) << c.name << " row " << rows[r];
        EXPECT_EQ(p.aStar[i], full.aStar[rows[r]]) << c.name << " row " << rows[r];
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(Schedule, ActiveSubsystemNeedsOneFlagPerConstraint) {
  System sys;
  sys.constraints.resize(2);
  EXPECT_THROW(activeSubsystem(sys, {true}), std::invalid_argument);
}

}  // namespace
}  // namespace proxgen

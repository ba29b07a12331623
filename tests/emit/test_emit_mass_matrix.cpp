// The shape of the generated mass_matrix (emit/pass_mass_matrix.cpp): CRBA
// carries every dof's column up to each ancestor, O(n depth) work, and the
// emitter groups that walk by ancestor so that a body's descendants' columns
// are one loop (docs/dynamics.md, "CRBA's walk by ancestor"). The values are
// the harness's business (tests/generated: every solver holding mass_matrix
// against the generic crba); this checks that the code stays O(n) and that
// the composite inertias are carried by their ten parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "emit/symbolic.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The generated source of mass_matrix alone for a serial chain of n links on
// a fixed base (depth n: the walk is n (n - 1) / 2 column steps).
std::string massMatrixSource(int n) { return test::syntheticChainFiles(n + 1, "mass_matrix").source; }

long massMatrixLines(int n) {
  const std::string source = massMatrixSource(n);
  return long(std::count(source.begin(), source.end(), '\n'));
}

// From 16 to 64 links, code linear in n grows 4 times, and the fixed part of
// the file (banner, entry point, the runtime's helpers) makes it a little less;
// the column-by-column walk it replaced grew 11 times (1,459 -> 16,151 lines:
// its n^2 / 2 steps), this one 4.3 (1,097 -> 4,669; both measured with this
// test). The bound, 6, sits between them: a walk whose code grows
// with the depth again fails it, and an O(n) pass that prints a few more lines
// per body does not.
TEST(MassMatrixCode, TheWalkIsLinearInTheDepth) {
  const long small = massMatrixLines(16), large = massMatrixLines(64);
  ASSERT_GT(small, 0);
  EXPECT_LT(double(large) / double(small), 6.0) << small << " lines at 16 links, " << large << " at 64";
}

// Every column loop is printed after PROXGEN_RT_NO_UNROLL (column_loops.cpp,
// columnLoopHead): GCC would otherwise peel the short ones completely, code
// that a large robot runs once per call (docs/benchmarks.md, "The column loops
// kept loops by the compiler").
TEST(MassMatrixCode, ColumnLoopsAreKeptLoops) {
  const std::string source = massMatrixSource(16);
  const long loops = test::occurrences(source, "for (int j = 0; j < ");
  EXPECT_GT(loops, 0);
  EXPECT_EQ(test::occurrences(source, "PROXGEN_RT_NO_UNROLL for (int j = 0; j < "), loops);
}

// In a serial chain every body but the root's child has a single-child
// parent, so the descendants' columns wait and go up kChainSteps (3) bodies per
// loop, with no store of Fcol between the steps (pass_mass_matrix.cpp; the
// walk by ancestor before it printed one loop per body, its label "body i
// 'name'"). Every loop's label names the bodies it goes through.
TEST(MassMatrixCode, ColumnsGoUpSingleChildChainsInOneLoop) {
  const std::string source = massMatrixSource(16);
  long loops = 0, chained = 0;
  std::size_t at = 0;
  for (std::string line; at < source.size(); at += line.size() + 1) {
    line = source.substr(at, source.find('\n', at) - at);
    if (line.find("subtree columns to the parent, columns") == std::string::npos) continue;
    ++loops;
    if (line.find("// bodies ") != std::string::npos) ++chained;
  }
  ASSERT_GT(loops, 0);
  EXPECT_EQ(chained, loops) << "column loops through one body only";
  EXPECT_LE(loops, 16 / 3 + 1) << "one loop per three bodies of the chain";
}

// rigidToParent (symbolic.hpp) against the general congruence F M F^T of the
// same inertia's 6 x 6, on constant inputs (every entry folds to a number):
// random bodies (mass, centre of mass, a positive definite inertia) under
// random placements. The two sum the same products in other orders, so they
// agree to round-off: every term of an entry is at most the scale
// S = |Ic| + m (|c| + |p|)^2 (the parallel-axis terms of the shifted centre),
// each entry is a sum of fewer than 32 rounded terms, so the two differ by
// less than 64 u S (u = 2^-53), whatever cancellation the entry itself has.
TEST(MassMatrixCode, CompositeInertiaToTheParentIsTheCongruence) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Inertia body;
    body.mass = 0.1 + 5.0 * (u(gen) + 1.0);
    body.com = Vec3(u(gen), u(gen), u(gen));
    Mat3 A;
    A << u(gen), u(gen), u(gen), u(gen), u(gen), u(gen), u(gen), u(gen), u(gen);
    body.Ic = A * A.transpose() + 0.01 * Mat3::Identity();
    SE3 X;
    X.R = rpyToMatrix(Vec3(3.0 * u(gen), 3.0 * u(gen), 3.0 * u(gen)));
    X.p = Vec3(u(gen), u(gen), u(gen));
    if (trial % 5 == 0) X.p.setZero();  // a joint's rotation alone
    if (trial % 7 == 0) X.R.setIdentity();  // a tree placement's shift alone
    CodeBuilder cb(ScalarType::Double);
    const Sym M = constant(body.matrix());
    const Sym viaCongruence = congruence(cb, constant(X), M);
    const Sym viaRigid = spatial(rigidToParent(cb, constant(X), rigidOf(M)));
    const double reach = body.com.norm() + X.p.norm();
    const double scale = body.Ic.cwiseAbs().maxCoeff() + body.mass * reach * reach;
    const double bound = 64.0 * 0x1p-53 * scale;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) {
        ASSERT_TRUE(viaCongruence(i, j).isConstant() && viaRigid(i, j).isConstant()) << i << ", " << j;
        EXPECT_NEAR(viaRigid(i, j).constant(), viaCongruence(i, j).constant(), bound)
            << "trial " << trial << ", entry (" << i << ", " << j << ")";
      }
  }
}

long largestIcMember(const std::string& header) {
  long largest = 0;
  for (auto at = header.find(" Ic_"); at != std::string::npos; at = header.find(" Ic_", at + 1)) {
    const auto open = header.find('[', at), close = header.find(']', at);
    if (open == std::string::npos || close < open) continue;
    largest = std::max(largest, std::stol(header.substr(open + 1, close - open - 1)));
  }
  return largest;
}

// A composite inertia varies with q in h = m c and I only: a member of 9
// entries per body in the workspace, not the 21 of a symmetric 6 x 6 (the
// member's size before the composite inertias were carried by their
// parameters: on the Atlas, whose general joint axes hide the constant mass
// block and the skew coupling from the symbolic algebra, all 21 were stored).
TEST(MassMatrixCode, CompositeInertiasHaveNineEntries) {
  const SolverFiles files = test::syntheticChainFiles(4, "mass_matrix");
  EXPECT_EQ(largestIcMember(files.header), 9) << "the workspace's composite inertias";
}

}  // namespace
}  // namespace proxgen::emit

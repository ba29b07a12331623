// The shape of the generated mass_matrix (emit/pass_mass_matrix.cpp): CRBA
// carries every dof's column up to each ancestor, O(n depth) work, and the
// emitter groups that walk by ancestor so that a body's descendants' columns
// are one loop (docs/dynamics.md, "CRBA's walk by ancestor"). The values are
// the harness's business (tests/generated: every solver holding mass_matrix
// against the generic crba); this checks that the code stays O(n).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

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

long count(const std::string& text, const std::string& what) {
  long n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
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
  const long loops = count(source, "for (int j = 0; j < ");
  EXPECT_GT(loops, 0);
  EXPECT_EQ(count(source, "PROXGEN_RT_NO_UNROLL for (int j = 0; j < "), loops);
}

}  // namespace
}  // namespace proxgen::emit

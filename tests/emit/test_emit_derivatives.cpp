// The shape of the derivatives' tangent sweep (emit/pass_inverse_dynamics_derivatives.cpp):
// in the world frame, one block per body forward and one backward, the (dof,
// path dof) pairs in two loops over constant tables, the free flyer's
// translation columns of dtau_dq left out (docs/derivatives.md section 5);
// and the shape of constrained_dynamics_derivatives' dense algebra (section 5 there).
// The values are the harness's business (tests/generated: harness_derivatives.cpp).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The ranges of a `static constexpr int <name>_span[...] = {lo, hi, ...};` table.
std::vector<std::pair<int, int>> spanTable(const std::string& source, const std::string& name) {
  const std::regex table("static constexpr int " + name + R"(_span\[\d+\] = \{([^}]*)\};)");
  std::smatch m;
  if (!std::regex_search(source, m, table)) return {};
  std::vector<int> x;
  const std::string list = m[1].str();
  for (std::size_t at = 0; at < list.size();) {
    std::size_t next = 0;
    x.push_back(std::stoi(list.substr(at), &next));
    at += next;
    while (at < list.size() && (list[at] == ',' || list[at] == ' ')) ++at;
  }
  std::vector<std::pair<int, int>> out;
  for (std::size_t k = 0; k + 1 < x.size(); k += 2) out.push_back({x[k], x[k + 1]});
  return out;
}

// The entries `<out>[k] = ...` printed straight-line, by index k.
std::vector<int> printedEntries(const std::string& source, const std::string& out) {
  const std::regex line("\n  " + out + R"(\[(\d+)\] = )");
  std::vector<int> k;
  for (auto it = std::sregex_iterator(source.begin(), source.end(), line); it != std::sregex_iterator(); ++it)
    k.push_back(std::stoi((*it)[1].str()));
  return k;
}

TEST(DerivativesCode, TheWorldFrameSweepVisitsEachBodyOnceAndLoopsOverThePairs) {
  // 24 revolute joints in a chain (nv = 24: 2 * 24^2 entries of dtau, above
  // kPairsInlinedUpTo), the source as the passes printed it.
  const int n = 24;
  const std::string source = test::syntheticChainFiles(n + 1, "inverse_dynamics_derivatives").unsharedSource;
  // One block per body and pass: a body-frame sweep prints a block per carried
  // column instead (300 forward blocks for this chain).
  EXPECT_EQ(test::occurrences(source, "// world forward body "), n);
  EXPECT_EQ(test::occurrences(source, "// world columns body "), n);
  // No per-body tangent members: with no constraint nothing reads them.
  EXPECT_EQ(source.find("w.dvq_"), std::string::npos);
  // The pairs: rows of dtau_dq and dtau_dv, and the ancestors' rows, in loops.
  EXPECT_EQ(test::occurrences(source, "world_frame_rows<24>("), 2);
  EXPECT_EQ(test::occurrences(source, "world_frame_columns<24>("), 1);
  EXPECT_TRUE(printedEntries(source, "dtau_dq").empty());
  // Row r's path in a chain is dofs 0..r; dof c's strict subtree is c + 1..n-1.
  std::vector<std::pair<int, int>> path;
  std::string below;
  for (int r = 0; r < n; ++r) path.push_back({0, r + 1});
  for (int c = 0; c < n; ++c) below += fmt::format("{}{}, {}", c == 0 ? "" : ", ", c + 1, n);
  EXPECT_EQ(spanTable(source, "path_v"), path);
  EXPECT_EQ(spanTable(source, "path_q"), path);  // the first joint (about x) moves under gravity (along z)
  const std::regex belowTable(R"(static constexpr int below\[48\] = \{([^}]*)\};)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(source, m, belowTable));
  EXPECT_EQ(m[1].str(), below);
}

TEST(DerivativesCode, ASmallRobotsPairsAreStraightLine) {
  // 7 revolute joints in a chain: 49 entries of each matrix can be nonzero (a
  // chain couples every pair), each printed once, no loop over tables.
  const std::string source = test::syntheticChainFiles(8, "inverse_dynamics_derivatives").unsharedSource;
  EXPECT_EQ(source.find("world_frame_rows<7>("), std::string::npos);
  EXPECT_EQ(source.find("world_frame_columns<7>("), std::string::npos);
  for (const char* out : {"dtau_dq", "dtau_dv"}) {
    std::vector<int> k = printedEntries(source, out);
    std::sort(k.begin(), k.end());
    std::vector<int> all(49);
    for (int i = 0; i < 49; ++i) all[std::size_t(i)] = i;
    EXPECT_EQ(k, all) << out;
  }
}

TEST(DerivativesCode, TheFreeFlyersTranslationsLeaveDtauDqOut) {
  // Moving the whole robot along a straight line changes none of its dynamics
  // (gravity is uniform): u = s x ov_0 = 0 and c = -s x oa_0 = 0 for a linear
  // s, so those columns of dtau_dq are exact zeros and nothing computes them;
  // dtau_dv's are not (the quadruped: q = [base position, quaternion, joints],
  // dq = [linear; angular; joints], nv = 18, its pairs straight-line).
  const std::string dir = test::sourceDir() + "/generated/quadruped";
  GenerateOptions g;
  g.urdf = dir + "/quadruped.urdf";
  g.layout = dir + "/layout.yaml";
  g.name = "quadruped";
  g.functions = "inverse_dynamics_derivatives";
  const std::string source = generateFiles(g).source;
  const std::vector<int> q = printedEntries(source, "dtau_dq"), v = printedEntries(source, "dtau_dv");
  ASSERT_FALSE(q.empty());
  long translations = 0;
  for (int k : q)
    if (k % 18 < 3 && k / 18 >= 6) ++translations;  // a joint's row, a translation column: must be absent
  EXPECT_EQ(translations, 0);
  // The root's own rows' translation columns are not printed either; dtau_dv has all of them.
  for (int k : q) EXPECT_GE(k % 18, 3) << "dtau_dq entry " << k;
  long vTranslations = 0;
  for (int k : v) vTranslations += k % 18 < 3 ? 1 : 0;
  EXPECT_EQ(vTranslations, 18 * 3);
}

// constrained_dynamics_derivatives through the tau block: W = M^-1 J^T meets
// one nc x nv block (P = M^-1 - W Lt, by blocks of 8 rows up to their last
// column, the rest mirrored), and each input's two outputs come from one pair
// of products over rows of nv + nc with its sparse tangents on the left. The
// literal form multiplied W by each input's block (three full nv x nv products).
TEST(DerivativesCode, TheConstrainedAlgebraGoesThroughTheTauBlock) {
  // 11 revolute joints in a chain (nv = 11: two blocks of P), a 3d point on the tip (nc = 3).
  const std::string source =
      test::syntheticChainFiles(12, "constrained_dynamics_derivatives", "- {name: tip, link: l11, type: 3d}").source;
  // W's products: the two blocks of P's rows, each up to its last column.
  EXPECT_EQ(test::occurrences(source, "dense_product_add<"), 2);
  EXPECT_EQ(test::occurrences(source, "dense_product_add<8, 3, 8, 14, 14>(w.cdd_MinvJt, w.cdd_LtS"), 1);
  EXPECT_EQ(test::occurrences(source, "dense_product_add<3, 3, 11, 14, 14>(w.cdd_MinvJt + 24, w.cdd_LtS"), 1);
  // Rows 0..7's columns 8..10 from rows 8..10.
  EXPECT_EQ(test::occurrences(source, "w.cdd_PLt[i * 14 + 8 + j] = w.cdd_PLt[j * 14 + 112 + i];"), 1);
  // Per input q, v: -dtau_dx^T [P | Lt^T] + R2_x^T [Lt | -S_K], rows of 14.
  EXPECT_EQ(test::occurrences(source, "sparse_transposed_product<11, 11, 14>("), 2);
  EXPECT_EQ(test::occurrences(source, "sparse_transposed_product_add<11, 3, 14, 22>("), 2);
}

}  // namespace
}  // namespace proxgen::emit

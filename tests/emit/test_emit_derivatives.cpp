// The shape of the derivatives' tangent sweep (emit/pass_inverse_dynamics_derivatives.cpp):
// a body's velocity map B (dv -> dv x* I v + v x* I dv, B = H(I v) + (v x*) I),
// which every column's force tangent reads, is formed once in the body's own
// block and stored for its carried columns, whose parts would otherwise form
// the cross products with I v and I dv again for each column (docs/derivatives.md);
// and the shape of constrained_dynamics_derivatives' dense algebra (section 5 there).
// The values are the harness's business (tests/generated: harness_derivatives.cpp).
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>

#include "support.hpp"

namespace proxgen::emit {
namespace {

TEST(DerivativesCode, EachBodysVelocityMapIsStoredOnce) {
  // 7 revolute joints in a chain, the source as the passes printed it (shared
  // blocks would print a store once for several bodies).
  const std::string source = test::syntheticChainFiles(8, "inverse_dynamics_derivatives").unsharedSource;
  // Stores `w.Bv_<body>[e] = ...` (entry e = 6 column + row), counted per (body, e).
  std::map<std::string, int> stores;
  const std::regex store(R"(w\.(Bv_\w+\[\d+\]) = )");
  for (auto it = std::sregex_iterator(source.begin(), source.end(), store); it != std::sregex_iterator(); ++it)
    ++stores[(*it)[1].str()];
  // The bodies below the first carry their ancestors' columns: 6 bodies, each
  // with the entries of B that are not constant (a revolute joint's body has
  // some: at least the 18 of H(I v) and of the products with v's three angular entries).
  std::map<std::string, int> bodies;
  for (const auto& [slot, n] : stores) {
    EXPECT_EQ(n, 1) << slot << " stored more than once";
    ++bodies[slot.substr(0, slot.find('['))];
  }
  EXPECT_EQ(bodies.size(), 6u);
  for (const auto& [body, entries] : bodies) EXPECT_GE(entries, 18) << body;
  // Read back, not recomputed, by the carried columns' parts: more uses than stores.
  long uses = 0;
  for (auto at = source.find("w.Bv_"); at != std::string::npos; at = source.find("w.Bv_", at + 1)) ++uses;
  EXPECT_GT(uses, long(stores.size()));
  // The momentum itself is not a member any more: only B reads it, in the body's block.
  EXPECT_EQ(source.find("w.Iv_"), std::string::npos);
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

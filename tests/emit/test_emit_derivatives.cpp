// The shape of the derivatives' tangent sweep (emit/pass_inverse_dynamics_derivatives.cpp):
// a body's momentum I v, which every column's force tangent dv x* I v reads,
// is computed once in the body's own block and stored for its carried columns,
// whose parts used to compute it again each (docs/derivatives.md). The values
// are the harness's business (tests/generated: harness_derivatives.cpp).
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>

#include "support.hpp"

namespace proxgen::emit {
namespace {

TEST(DerivativesCode, EachBodysMomentumIsStoredOnce) {
  // 7 revolute joints in a chain, the source as the passes printed it (shared
  // blocks would print a store once for several bodies).
  const std::string source = test::syntheticChainFiles(8, "inverse_dynamics_derivatives").unsharedSource;
  // Stores `w.Iv_<body>[r] = ...`, counted per (body, r).
  std::map<std::string, int> stores;
  const std::regex store(R"(w\.(Iv_\w+\[\d\]) = )");
  for (auto it = std::sregex_iterator(source.begin(), source.end(), store); it != std::sregex_iterator(); ++it)
    ++stores[(*it)[1].str()];
  // The bodies below the first carry their ancestors' columns: 6 bodies.
  std::map<std::string, int> bodies;
  for (const auto& [slot, n] : stores) {
    EXPECT_EQ(n, 1) << slot << " stored more than once";
    ++bodies[slot.substr(0, slot.find('['))];
  }
  EXPECT_EQ(bodies.size(), 6u);
  // And read back, not recomputed, by the carried columns' parts: more uses than stores.
  long uses = 0;
  for (auto at = source.find("w.Iv_"); at != std::string::npos; at = source.find("w.Iv_", at + 1)) ++uses;
  EXPECT_GT(uses, long(stores.size()));
}

}  // namespace
}  // namespace proxgen::emit

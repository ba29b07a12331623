// The names and slots of a generated header (issue 18 item 4; docs/design.md,
// "Names in the generated files"): joint:: and constraint:: hold the names
// sanitised and made unique as the rest of the file makes them, and the string
// arrays hold the raw names in literals that decode to exactly their bytes
// and carry nothing a raw name could break the file with. (The generated
// harness, tests/generated/harness.cpp, compiles the hostile solvers and
// compares the arrays with the Model byte for byte.)
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "emit/assemble.hpp"
#include "emit/generate.hpp"
#include "emit/identifiers.hpp"
#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The `inline constexpr int <id> = <k>;` lines of `namespace <ns> { ... }`.
std::vector<std::pair<std::string, int>> indices(const std::string& header, const std::string& ns) {
  const std::size_t from = header.find("namespace " + ns + " {"), to = header.find("}  // namespace " + ns);
  EXPECT_NE(from, std::string::npos) << ns;
  EXPECT_NE(to, std::string::npos) << ns;
  std::vector<std::pair<std::string, int>> out;
  if (from == std::string::npos || to == std::string::npos) return out;
  const std::string block = header.substr(from, to - from);
  static const std::regex line(R"(inline constexpr int (\w+) = (\d+);)");
  for (auto it = std::sregex_iterator(block.begin(), block.end(), line); it != std::sregex_iterator(); ++it)
    out.push_back({(*it)[1].str(), std::stoi((*it)[2].str())});
  return out;
}

// A C string literal's bytes (the escapes cStringLiteral writes, nothing else).
std::string decode(const std::string& literal) {
  EXPECT_GE(literal.size(), 2u);
  EXPECT_EQ(literal.front(), '"');
  EXPECT_EQ(literal.back(), '"');
  std::string out;
  for (std::size_t k = 1; k + 1 < literal.size(); ++k) {
    if (literal[k] != '\\') {
      EXPECT_NE(literal[k], '"') << literal;
      out += literal[k];
      continue;
    }
    const char n = literal[k + 1];
    if (n == '"' || n == '\\' || n == '?') {
      out += n;
      ++k;
    } else {
      out += char(std::stoi(literal.substr(k + 1, 3), nullptr, 8));
      k += 3;
    }
  }
  return out;
}

// Generation options for a fixture of tests/data/hostile: STEM.urdf and STEM.yaml.
GenerateOptions hostile(const std::string& stem, const std::string& name) {
  const std::string dir = test::sourceDir() + "/tests/data/hostile";
  GenerateOptions g;
  g.urdf = dir + "/" + stem + ".urdf";
  g.layout = dir + "/" + stem + ".yaml";
  g.name = name;
  return g;
}

TEST(HeaderNames, IndicesAreTheSanitisedUniqueNames) {
  const GenerateOptions g = hostile("names", "hostile");
  System sys;
  const SolverFiles files = generateFiles(g, nullptr, &sys);
  // The rule: sanitizeIdentifier, and a name taken already gets "_<position>".
  IdentifierSet jointIds, constraintIds;
  std::vector<std::pair<std::string, int>> joints, constraints;
  for (int i = 1; i < sys.model.numBodies(); ++i)
    joints.push_back({jointIds.make(sys.model.bodies[std::size_t(i)].joint.name, i - 1), i - 1});
  for (std::size_t k = 0; k < sys.constraints.size(); ++k)
    constraints.push_back({constraintIds.make(sys.constraints[k].name, int(k)), int(k)});
  EXPECT_EQ(indices(files.header, "joint"), joints);
  EXPECT_EQ(indices(files.header, "constraint"), constraints);
  // names.urdf has moving joints that sanitise alike (j-x, j.x, j_x) and
  // names.yaml two constraints (a-b, a.b): the suffix tells them apart.
  bool suffixed = false;
  for (const auto& [id, k] : joints) suffixed |= id.rfind("j_x_", 0) == 0;
  EXPECT_TRUE(suffixed);
  for (const auto& [id, k] : constraints) EXPECT_FALSE(isReservedIdentifier(id)) << id;
}

TEST(HeaderNames, StringLiteralsHoldExactlyTheBytes) {
  std::vector<std::string> names = {"base \"link\"", "j'1\\", "*/ int main() { return 1; } /*", "?\?/ ?\?= ?\?( ?\?) trigraphs",
                                    "line1\n#include <cstdlib>\n", "%s %n {} {0} {:x}", "tab\tcr\rend\\", "/*/**/*/",
                                    "\xc5\x82\xc4\x85" "cze", "\\x41B", "\\101" "7"};
  std::string all;
  for (int c = 1; c < 256; ++c) all += char(c);
  names.push_back(all);
  for (const std::string& name : names) {
    const std::string lit = cStringLiteral(name);
    EXPECT_EQ(decode(lit), name) << lit;
    for (char c : lit) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << lit;
    EXPECT_EQ(lit.find("??"), std::string::npos) << lit;
    EXPECT_EQ(lit.find("/*"), std::string::npos) << lit;
    EXPECT_EQ(lit.find("*/"), std::string::npos) << lit;
  }
}


// A part function is named after its host and its first body, so a link may
// spell another function of the file ("bodies" off the support made
// eliminate_free_bodies twice: a source that did not compile). The emitter
// reserves fileFunctionNames() for the parts; here, on helper_names.urdf with
// every function held, every function the source defines is defined once, and
// each one that is not a part (PROXGEN_RT_NOINLINE) is in that list, so a helper
// added to the file without its name there fails this test.
TEST(FileFunctions, EachNameIsDefinedOnceAndEveryHelperIsReserved) {
  GenerateOptions g = hostile("helper_names", "helper_names");
  g.functions = "all";
  const std::string source = generateFiles(g).source;
  // A definition starts a line: a part, a helper or entry point, or a template's
  // function on the line after its template head.
  static const std::regex definition(
      R"((?:^|\n)(PROXGEN_RT_NOINLINE )?(?:void|Scalar|bool|int) (\w+)\([^;{]*\)\s*(?:const\s*)?noexcept\s*\{)");
  std::map<std::string, int> defined;
  const std::vector<std::string>& reserved = fileFunctionNames();
  for (auto it = std::sregex_iterator(source.begin(), source.end(), definition); it != std::sregex_iterator(); ++it) {
    const std::string name = (*it)[2].str();
    ++defined[name];
    if ((*it)[1].matched) continue;  // a part
    EXPECT_NE(std::find(reserved.begin(), reserved.end(), name), reserved.end())
        << name << " is defined by the file but not in fileFunctionNames()";
  }
  for (const auto& [name, count] : defined) EXPECT_EQ(count, 1) << name;
  // The links of helper_names.urdf do collide: the parts took the suffix.
  EXPECT_EQ(defined.count("eliminate_free_bodies_2"), 1u);
  EXPECT_EQ(defined.count("accelerate_free_bodies_2"), 1u);
  // The check sees the helpers at all (a regex that matched nothing would pass).
  for (const char* helper : {"kinematics", "tangent_sweep", "world_frame_rows", "world_frame_columns", "mass_matrix_inverse_passes",
                             "mass_matrix_inverse_factored", "mass_matrix_inverse_forward",
                             "dense_product_add", "residual", "constrained_dynamics_derivatives"})
    EXPECT_EQ(defined.count(helper), 1u) << helper;
}

}  // namespace
}  // namespace proxgen::emit

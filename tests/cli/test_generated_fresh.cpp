// The checked-in solvers under generated/ are what the current generator
// writes for their checked-in inputs, byte for byte. When this fails, the
// generator or an input changed: regenerate with the command in the message
// and commit the result.
#include <gtest/gtest.h>

#include <sstream>
#include <utility>
#include <vector>

#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The first line where two texts differ, for the message.
std::string firstDifference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ea = !std::getline(sa, la), eb = !std::getline(sb, lb);
    if (ea && eb) return "(no line differs)";
    if (ea || eb || la != lb)
      return "line " + std::to_string(line) + ":\n  checked in: " + (ea ? "<end>" : la.substr(0, 160)) +
             "\n  generated:  " + (eb ? "<end>" : lb.substr(0, 160));
  }
}

// The four files the current generator writes for a checked-in example, by name.
std::vector<std::pair<std::string, std::string>> exampleFiles(const std::string& robot) {
  const std::string dir = test::sourceDir() + "/generated/" + robot;
  GenerateOptions g;
  g.urdf = dir + "/" + robot + ".urdf";
  g.layout = dir + "/layout.yaml";
  g.name = robot;
  const SolverFiles f = generateFiles(g);
  return {{f.headerName, f.header}, {f.sourceName, f.source}, {f.cHeaderName, f.cHeader}, {f.cSourceName, f.cSource}};
}

TEST(GeneratedFresh, CheckedInSolversMatchTheGenerator) {
  for (const char* robot : {"arm", "quadruped", "humanoid"}) {
    const std::string dir = test::sourceDir() + "/generated/" + robot;
    const std::string command = "proxgen generate generated/" + std::string(robot) + "/" + robot +
                                ".urdf --layout generated/" + robot + "/layout.yaml --out generated/" + robot +
                                " --name " + robot;
    for (const auto& [name, text] : exampleFiles(robot)) {
      const std::string path = dir + "/" + name;
      const std::string checkedIn = test::slurp(path);
      EXPECT_EQ(checkedIn, text) << "generated/" << robot << "/" << name << " is stale ("
                                 << firstDifference(checkedIn, text) << ")\nregenerate it with:\n  " << command;
    }
  }
}

// The emitter promises printable ASCII (docs/design.md, "Bad input"): a
// compiler's source character set beyond it is implementation-defined, and a
// controller's toolchain may read the file in any code page. The fuzz target
// fuzz_emit checks the same on mutated inputs; this checks every file the
// three examples are generated into, templates included, in the ordinary run.
TEST(GeneratedFresh, GeneratedTextIsPrintableAscii) {
  for (const char* robot : {"arm", "quadruped", "humanoid"}) {
    for (const auto& [name, text] : exampleFiles(robot)) {
      std::istringstream in(text);
      int line = 1;
      for (std::string l; std::getline(in, l); ++line)
        for (unsigned char c : l) {
          ASSERT_TRUE(c >= 0x20 && c <= 0x7e) << name << " line " << line << ": byte " << int(c) << " in: " << l;
        }
    }
  }
}

}  // namespace
}  // namespace proxgen::emit

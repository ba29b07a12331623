// The layout's `functions: [...]` (model/functions.hpp): which functions a
// generated solver holds. Absent: the two solvers. Unknown, repeated or no
// names are one-line errors naming the file, the line, the element and the
// valid names.
#include <gtest/gtest.h>

#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::errorOf;

void expectMessage(const std::string& message, std::initializer_list<std::string> parts) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

TEST(LayoutFunctions, AbsentMeansTheTwoSolvers) {
  const Layout L = parseLayout("mu: 100\n", "l.yaml");
  EXPECT_EQ(L.functions.names(), (std::vector<std::string>{"constrained_aba", "prox_pv"}));
}

TEST(LayoutFunctions, ListedNamesAreExactlyTheSet) {
  const Layout L = parseLayout("functions: [mass_matrix, inverse_dynamics]\n", "l.yaml");
  // names() lists them in allFunctions() order, not the layout's.
  EXPECT_EQ(L.functions.names(), (std::vector<std::string>{"inverse_dynamics", "mass_matrix"}));
  EXPECT_FALSE(L.functions.has(Function::ConstrainedAba));
  const Layout block = parseLayout("functions:\n  - prox_pv\n", "l.yaml");
  EXPECT_EQ(block.functions.names(), (std::vector<std::string>{"prox_pv"}));
}

TEST(LayoutFunctions, BindLayoutCarriesThemIntoTheSystem) {
  test::TempFile f(".yaml");
  f.write("functions: [mass_matrix]\n");
  const System sys = loadSystem(test::sourceDir() + "/tests/data/good/arm3.urdf", f.path());
  EXPECT_EQ(sys.functions.names(), (std::vector<std::string>{"mass_matrix"}));
}

TEST(LayoutFunctions, AnUnknownNameNamesTheValidOnes) {
  const std::string m = errorOf([] { parseLayout("mu: 10\nfunctions: [mass_matrix, rnea]\n", "l.yaml"); });
  expectMessage(m, {"l.yaml:2", "functions[1]", "unknown function 'rnea'", "constrained_aba", "mass_matrix_inverse",
                    "delassus_inverse"});
}

TEST(LayoutFunctions, RepeatedEmptyAndMistypedListsAreErrors) {
  expectMessage(errorOf([] { parseLayout("functions: [mass_matrix, mass_matrix]\n", "l.yaml"); }),
                {"l.yaml:1", "functions[1]", "listed twice"});
  expectMessage(errorOf([] { parseLayout("functions: []\n", "l.yaml"); }), {"l.yaml:1", "functions", "is empty", "prox_pv"});
  expectMessage(errorOf([] { parseLayout("functions: mass_matrix\n", "l.yaml"); }),
                {"l.yaml:1", "functions", "expected a list", "prox_pv"});
  expectMessage(errorOf([] { parseLayout("functions:\n", "l.yaml"); }), {"functions", "expected a list"});
  expectMessage(errorOf([] { parseLayout("functions: [[mass_matrix]]\n", "l.yaml"); }), {"functions[0]", "expected a string"});
}

TEST(LayoutFunctions, TheCommandLinesListParsesAlike) {
  EXPECT_EQ(parseFunctionList("all", "command line", "--functions").names().size(), allFunctions().size());
  EXPECT_EQ(parseFunctionList("mass_matrix,prox_pv", "command line", "--functions").names(),
            (std::vector<std::string>{"prox_pv", "mass_matrix"}));
  expectMessage(errorOf([] { parseFunctionList("mass_matrix,crba", "command line", "--functions"); }),
                {"command line", "--functions", "unknown function 'crba'", "inverse_dynamics", "or all"});
  expectMessage(errorOf([] { parseFunctionList("", "command line", "--functions"); }), {"--functions", "unknown function ''"});
}

}  // namespace
}  // namespace proxgen

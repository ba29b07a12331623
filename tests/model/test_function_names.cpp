// The names of a solver's functions (model/functions.hpp): the one spelling the
// layout, the command line and CMake share, and the errors a typo gets.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "model/error.hpp"
#include "model/functions.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::errorOf;

TEST(Functions, DefaultIsTheTwoSolvers) {
  // Existing users' solvers must not grow: without a list, only the solvers.
  const FunctionSet d;
  EXPECT_EQ(d.names(), (std::vector<std::string>{"constrained_aba", "prox_pv"}));
}

TEST(Functions, EveryNameRoundTripsAndIsUnique) {
  std::set<std::string> seen;
  for (Function f : allFunctions()) {
    const std::string name = functionName(f);
    EXPECT_TRUE(seen.insert(name).second) << name;
    Function back;
    ASSERT_TRUE(parseFunctionName(name, back)) << name;
    EXPECT_EQ(back, f) << name;
    EXPECT_NE(functionNameList().find(name), std::string::npos) << name;
  }
  EXPECT_EQ(FunctionSet::all().names().size(), allFunctions().size());
  EXPECT_TRUE(FunctionSet::none().empty());
}

TEST(Functions, ListKeepsExactlyWhatIsNamed) {
  const FunctionSet s = parseFunctionList("mass_matrix,delassus_inverse", "cli", "--functions");
  EXPECT_EQ(s.names(), (std::vector<std::string>{"mass_matrix", "delassus_inverse"}));
  EXPECT_FALSE(s.has(Function::ConstrainedAba));
  EXPECT_EQ(parseFunctionList("all", "cli", "--functions"), FunctionSet::all());
}

TEST(Functions, BadListsNameTheFileElementAndValidNames) {
  const std::string unknown = errorOf([] { parseFunctionList("mass_matrx", "l.yaml:3", "functions"); });
  EXPECT_NE(unknown.find("l.yaml:3: functions:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("'mass_matrx'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find(functionNameList()), std::string::npos) << unknown;

  const std::string twice = errorOf([] { parseFunctionList("prox_pv,prox_pv", "cli", "--functions"); });
  EXPECT_NE(twice.find("listed twice"), std::string::npos) << twice;

  // An empty name (",", a trailing comma, "") is a typo, not a request for nothing.
  for (const char* list : {"", ",", "prox_pv,", ",prox_pv"})
    EXPECT_NE(errorOf([&] { parseFunctionList(list, "cli", "--functions"); }).find("unknown function"),
              std::string::npos)
        << "'" << list << "'";
}

}  // namespace
}  // namespace proxgen

// The shape of proxPV's Delassus factor with a floating base
// (emit/pass_delassus_factor.cpp): G + I/mu = A + I/mu + Z^T Z goes through
// Woodbury, W = L^-1 Z^T and S = I + W^T W, and since the six columns of W go
// through the same arithmetic each row of W and each row of S is one loop over
// the columns (docs/emitter.md, "Woodbury's rows as loops"). The values are the
// harnesses' business (tests/generated: the shared cases' prox_pv against the
// generic one, double and float; tests/cli/test_verify_models.cpp: the
// Cartesian legs below); this checks the code's shape. With six rows or fewer
// there is no split: G + I/mu is factored whole. A column's entries below the
// diagonal of one shape (the same terms, each read one slot further per row)
// are one loop over the rows (docs/emitter.md, "The Delassus columns as loops").
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>
#include <vector>

#include "cases/cases.hpp"
#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The line after the first line holding `what`.
std::string lineAfter(const std::string& text, const std::string& what) {
  const std::size_t at = text.find(what);
  if (at == std::string::npos) return {};
  const std::size_t next = text.find('\n', at) + 1;
  return text.substr(next, text.find('\n', next) - next);
}

// The body of the function `name`: from its name to its closing brace (the first "}" alone on a line).
std::string functionBody(const std::string& source, const std::string& name) {
  const std::size_t at = source.find(" " + name + "(");
  if (at == std::string::npos) return {};
  return source.substr(at, source.find("\n}\n", at) - at);
}

// The terms of a sum as printed: split at each " + " and " - " outside brackets.
std::vector<std::string> termsOf(const std::string& sum) {
  std::vector<std::string> terms(1);
  int depth = 0;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const char c = sum[i];
    depth += (c == '[' || c == '(') - (c == ']' || c == ')');
    if (depth == 0 && c == ' ' && i + 2 < sum.size() && (sum[i + 1] == '+' || sum[i + 1] == '-') && sum[i + 2] == ' ') {
      terms.emplace_back();
      i += 2;
      continue;
    }
    terms.back() += c;
  }
  return terms;
}

// In every statement of `body` that reads temporaries (t12, w0, v1, z3) of
// earlier statements, the one defined last is read in the last term: a
// solve's row subtracts the row solved just before it last, so the rest of
// its sum runs while that row is being solved (docs/emitter.md, "The solves'
// sums in the order their terms are known"). Returns the statements that
// break it.
std::vector<std::string> latestOperandNotLast(const std::string& body) {
  static const std::regex statement(R"(const Scalar (\w+) = (.*);)");
  static const std::regex temporary(R"(\b([twvz]\d+)\b)");
  std::map<std::string, int> definedAt;
  std::vector<std::string> broken;
  int line = 0;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), statement); it != std::sregex_iterator(); ++it, ++line) {
    const std::string rhs = (*it)[2].str();
    std::string latest;
    for (auto t = std::sregex_iterator(rhs.begin(), rhs.end(), temporary); t != std::sregex_iterator(); ++t)
      if (definedAt.count((*t)[1].str()) && (latest.empty() || definedAt[(*t)[1].str()] > definedAt[latest]))
        latest = (*t)[1].str();
    const std::vector<std::string> terms = termsOf(rhs);
    if (!latest.empty() && !std::regex_search(terms.back(), std::regex("\\b" + latest + "\\b")))
      broken.push_back((*it)[0].str());
    definedAt[(*it)[1].str()] = line;
  }
  return broken;
}

// proxPV of the Cartesian leg (tests/data/good/cartesian_leg.urdf and .yaml): a
// floating base whose leg's rows reach the free flyer unturned.
SolverFiles cartesianLegProxPv() {
  GenerateOptions g;
  g.urdf = test::sourceDir() + "/tests/data/good/cartesian_leg.urdf";
  g.layout = test::sourceDir() + "/tests/data/good/cartesian_leg.yaml";
  g.functions = "prox_pv";
  return generateFiles(g);
}

// Every row of W is a loop over the six columns, S's rows loops over the
// columns of its upper triangle, and no column of W is unrolled.
void expectWoodburyRows(const std::string& source, int rows) {
  EXPECT_EQ(test::occurrences(source, "// W = L^-1 Z^T, row "), rows);
  EXPECT_EQ(test::occurrences(source, "// W = L^-1 Z^T, column"), 0) << "a column of W unrolled";
  for (int t = 0; t < rows; ++t)
    EXPECT_EQ(lineAfter(source, "// W = L^-1 Z^T, row " + std::to_string(t) + ","),
              "  PROXGEN_RT_NO_UNROLL for (int j = 0; j < 6; ++j) {")
        << "row " << t;
  for (int a = 0; a < 6; ++a)
    EXPECT_EQ(lineAfter(source, "// W^T W, row " + std::to_string(a) + ","),
              "  PROXGEN_RT_NO_UNROLL for (int j = 0; j < " + std::to_string(6 - a) + "; ++j) {")
        << "row " << a << " of S";
}

// Solo's four feet (12 rows, no branch) and the Atlas' feet and two hands of
// ten fingertip rows each (42 rows; the hands' blocks meet through the torso
// in low rank, so W's rows after the first hand's subtract its terms, Wlr0).
TEST(DelassusCode, WoodburyRowsAreLoopsOverTheSixColumns) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  const SolverFiles solo = generateCase(cases, "solo_f3x4", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  expectWoodburyRows(solo.source, 12);
  EXPECT_EQ(test::occurrences(solo.source, "Wlr"), 0);
  const SolverFiles atlas =
      generateCase(cases, "atlas_shadow_f6x2_t3x10", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  expectWoodburyRows(atlas.source, 42);
  EXPECT_GT(test::occurrences(atlas.source, "// W's low-rank terms, branch 0"), 0);
  EXPECT_GT(test::occurrences(atlas.header, "Scalar Wlr0["), 0);
}

// With six rows or fewer the split would factor a 6 x 6 capacitance as large
// as G itself on top of W: solo_f3x2 (two feet, 6 rows) factors G + I/mu
// whole, the free flyer's Z^T Z in its entries (docs/emitter.md, "Woodbury
// from seven rows"), and its four-foot case (12 rows) keeps the split.
TEST(DelassusCode, SixRowsOrFewerFactorTheWholeMatrix) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  const SolverFiles two = generateCase(cases, "solo_f3x2", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  EXPECT_EQ(test::occurrences(two.source, "L^-1 Z^T"), 0);
  EXPECT_EQ(test::occurrences(two.header, "Scalar LS["), 0);
  const std::size_t at = two.source.find("// G + I/mu = L L^T, column 5 (");
  ASSERT_NE(at, std::string::npos);
  const std::string column5 = two.source.substr(at, 600);
  EXPECT_GT(test::occurrences(column5, "w.Z_base_link[5][5]*w.Z_base_link[5][5]"), 0) << column5;
  const SolverFiles four = generateCase(cases, "solo_f3x4", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  EXPECT_GT(test::occurrences(four.header, "Scalar LS["), 0);
}

// A Cartesian leg's rows reach the free flyer unturned, so entries of Z fold
// (zeros of KA at the top of L^-1 KA): such a row is copied to Wz first, and
// the loops read it there (tests/data/good/cartesian_leg.urdf).
TEST(DelassusCode, ARowOfZWithFoldedEntriesIsStagedForTheLoops) {
  const SolverFiles f = cartesianLegProxPv();
  expectWoodburyRows(f.source, 9);
  EXPECT_GT(test::occurrences(f.source, "some entries folded: staged for the loops"), 0);
  EXPECT_GT(test::occurrences(f.source, "w.Wz[0][j]"), 0);
}

// At the free flyer every carried column goes through the same solve, Z = L^-1
// KA: where KA's entries are all stored (rows turned by the joints below), the
// columns are one loop, which the compiler vectorises, two columns per
// register (docs/emitter.md, "The free flyer's Z as a loop"). A Cartesian leg's
// columns have folded entries (zeros at the top of KA): they stay unrolled,
// their zeros folded.
TEST(DelassusCode, TheFreeFlyersColumnsOfZAreOneLoop) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  const SolverFiles solo = generateCase(cases, "solo_f3x4", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  EXPECT_EQ(lineAfter(solo.source, "// Z = L^-1 KA, columns 0 to 11"),
            "    PROXGEN_RT_NO_UNROLL for (int j = 0; j < 12; ++j) {")
      << solo.source.substr(solo.source.find("Z = L^-1"), 400);
  EXPECT_EQ(test::occurrences(solo.source, "w.Z_base_link[5][j] = "), 1);
  EXPECT_EQ(test::occurrences(solo.source, "w.Z_base_link[0][0] = "), 0) << "a column of Z unrolled";
  const SolverFiles atlas =
      generateCase(cases, "atlas_shadow_f6x2_t3x10", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  EXPECT_EQ(lineAfter(atlas.source, "// Z = L^-1 KA, columns 0 to 41"),
            "    PROXGEN_RT_NO_UNROLL for (int j = 0; j < 42; ++j) {");
  const SolverFiles leg = cartesianLegProxPv();
  EXPECT_EQ(test::occurrences(leg.source, "// Z = L^-1 KA, columns"), 0);
  EXPECT_GT(test::occurrences(leg.source, "w.Z_hull[5][0] = "), 0);
}

// The Atlas' right hand holds rows 15 to 29 (five fingertips, three rows
// each), which all meet at the palm: in column 19 (the second row of the
// fingertip of rows 18 to 20) the rows of the other fingertips, 21 to 29,
// are one loop that reads each row's activity factor from active_rows and the
// earlier columns one slot further per row; row 20, of the same fingertip as
// 19 (more bodies in common, no activity factors), stays unrolled.
TEST(DelassusCode, TheRowsOfAColumnOfOneShapeAreOneLoop) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  const SolverFiles atlas =
      generateCase(cases, "atlas_shadow_f6x2_t3x10", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  const std::size_t at = atlas.source.find("// G + I/mu = L L^T, column 19 (");
  ASSERT_NE(at, std::string::npos);
  const std::string column19 = atlas.source.substr(at, atlas.source.find("column 20 (", at) - at);
  EXPECT_EQ(lineAfter(column19, "// rows 21 to 29"), "    PROXGEN_RT_NO_UNROLL for (int j = 0; j < 9; ++j) {") << column19;
  EXPECT_GT(test::occurrences(column19, "w.active_rows[21 + j]*w.active[6]"), 0) << column19;
  EXPECT_GT(test::occurrences(column19, "w.L[604]*w.L[606 + j]"), 0) << column19;  // L(i, 18) L(19, 18)
  EXPECT_GT(test::occurrences(column19, "w.L[629 + j] = w.Linv[19]*"), 0) << column19;
  EXPECT_GT(test::occurrences(column19, "w.L[628] = "), 0) << "row 20 unrolled\n" << column19;
  EXPECT_GT(test::occurrences(atlas.header, "Scalar active_rows[42];"), 0);
  // Talos' four 6-d contacts fold a different set of terms into each row: no loop, no active_rows.
  const SolverFiles talos = generateCase(cases, "talos_f6x2_h6x2", "", ScalarType::Double, nullptr, nullptr, "prox_pv");
  EXPECT_EQ(test::occurrences(talos.header, "active_rows"), 0);
}

// The proximal step is a chain of solves (L forward, Woodbury's 6 x 6, L
// backward; on the Atlas t3x10 with its hands' blocks in low rank): every row
// waits for the row before it, so each row's sum must take that row last.
// Before 2026-12-07 the backward solves took x[i + 1] first, and the low-rank
// terms came after the rows: each row's whole sum waited (the Atlas t3x10's
// step took 0.61 us, now 0.46; docs/benchmarks.md, "The solves' sums in the
// order their terms are known").
TEST(DelassusCode, EachRowOfTheProximalSolvesTakesItsLatestTermLast) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = test::modelsDir() + "/cases.yaml";
  for (const char* c : {"solo_f3x4", "talos_f6x2_h6x2", "atlas_shadow_f6x2_t3x10"}) {
    const SolverFiles f = generateCase(cases, c, "", ScalarType::Double, nullptr, nullptr, "prox_pv");
    const std::string step = functionBody(f.source, "pv_proximal");
    ASSERT_GT(test::occurrences(step, "const Scalar "), 40) << c;
    for (const std::string& s : latestOperandNotLast(step)) ADD_FAILURE() << c << ": " << s;
  }
}

}  // namespace
}  // namespace proxgen::emit

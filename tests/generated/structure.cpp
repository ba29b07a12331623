// The shape of every generated solver built by tests/generated:
// - its .cpp has no loop or branch but the iteration loops over K (exact text
//   allow-listed), proxPV's loops over a run of constraint columns (a
//   literal trip count, `for (int j = 0; j < 30; ++j) {`) and the derivatives'
//   fixed-bound loops (one assignment per element over a literal count, the
//   dense product over its template bounds): no loop over bodies, no branch on
//   joint type;
// - it has no empty function (a body of nothing but static_cast<void>
//   of unused parameters): a pass that folds away prints no function;
// - its object references no heap (malloc, operator new, ...) and no exception
//   machinery (__cxa_throw, the personality routine, the unwinder).
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(s);
  while (std::getline(in, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The generated code has no string or character literals (names only reach
// comments), so removing // comments and the template's #include / #pragma
// lines leaves exactly the code (any other directive stays and is reported).
std::string stripComments(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("#include ", 0) == 0 || line == "#pragma once") continue;
    const std::size_t c = line.find("//");
    out += (c == std::string::npos ? line : line.substr(0, c)) + "\n";
  }
  return out;
}

bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Every loop or branch construct of `code`, as "keyword: statement head".
// Allowed: the constrainedABA loop (iterations 2..K), the proxPV loop (K
// steps), constrained_dynamics_derivatives' K - 1 steps of S_K, and loops over
// constraint columns with a literal trip count.
std::vector<std::string> forbiddenControlFlow(const std::string& code) {
  static const std::vector<std::string> allowed = {"for (int k = 2; k <= s.iterations; ++k) {",
                                                   "for (int k = 0; k < s.iterations; ++k) {",
                                                   "for (int k = 1; k < s.iterations; ++k) {"};
  // S_K's row templates recurse over the row index at compile time.
  static const std::regex rowRecursion(R"(if constexpr \(i < n\) \{)");
  static const std::regex columns(R"(for \(int j = 0; j < [1-9][0-9]*; \+\+j\) \{)");
  static const std::regex fixedLoop(
      R"( *(for \(int k = (?:0|[1-9][0-9]*); k < (?:[1-9][0-9]*|n \* n); \+\+k\) [A-Za-z_][A-Za-z0-9_.]*\[k\] = [^;{}?&|"']*;)"
      R"(|for \(int r = 0; r < n; \+\+r\)|for \(int c = 0; c < p; \+\+c\) \{)"
      R"(|for \(int k = 0; k < m; \+\+k\) sum \+= A\[r \* m \+ k\] \* B\[k \* p \+ c\];)"
      // constrained_dynamics_derivatives' helpers (Cholesky, proximal step, the
      // SE(3) Jacobian's series): a head alone, bounds a template argument, an
      // outer index or a literal.
      R"(|for \(int ([a-z]) = (0|1|[a-z]|[a-z] \+ 1|n - 1); \2 (<|<=|>=) ([a-z]|0|[1-9][0-9]*); (\+\+|--)\2\) \{)"
      // the sparse products' and the sweep's pairs' loops over a pattern's
      // ranges, their bounds read from the tables (constants:
      // sparseTablesNotConstant below; the pairs' rows_q, rows_v, below are
      // printed `static constexpr int` beside their calls).
      R"(|for \(int ([a-z]) = (start|span|rows)\[[^\]]+\]; \7 < \8\[[^\]]+\]; \+\+\7\) \{))");
  static const std::vector<std::string> keywords = {"for", "while", "do", "if", "else", "switch", "case", "goto"};
  std::vector<std::string> found;
  for (std::size_t k = 0; k < code.size(); ++k) {
    // Lines allowed whole, checked at their first character (the regex once
    // per line, not per character: the big sources are megabytes).
    if (k == 0 || code[k - 1] == '\n') {
      const std::size_t nl = code.find('\n', k);
      const std::string line = code.substr(k, nl == std::string::npos ? std::string::npos : nl - k);
      // inverse_dynamics' lambda == nullptr: a pointer select before any
      // arithmetic (docs/dynamics.md), the one conditional allowed; and the
      // derivatives' fixed-bound loops (docs/derivatives.md): the dense
      // product template, whose bounds are its template arguments, and one
      // element-wise assignment over literal bounds (also mass_matrix's runs
      // of zeros, docs/dynamics.md). No data decides a trip.
      if (line == "  lambda = lambda != nullptr ? lambda : kNoMultipliers;" || std::regex_match(line, fixedLoop)) {
        if (nl == std::string::npos) break;
        k = nl;
        continue;
      }
    }
    if (code[k] == '?' || code.compare(k, 2, "&&") == 0 || code.compare(k, 2, "||") == 0 || code[k] == '"' ||
        code[k] == '\'' || code[k] == '#') {
      found.push_back(code.substr(k, code.find('\n', k) - k));
      continue;
    }
    if (!identChar(code[k]) || (k > 0 && identChar(code[k - 1]))) continue;
    std::size_t end = k;
    while (end < code.size() && identChar(code[end])) ++end;
    const std::string word = code.substr(k, end - k);
    for (const std::string& kw : keywords) {
      if (word != kw) continue;
      const std::string head = code.substr(k, code.find('{', k) + 1 - k);
      bool ok = false;
      for (const std::string& a : allowed) ok |= head == a;
      ok |= std::regex_match(head, columns) || std::regex_match(head, rowRecursion);
      if (!ok) found.push_back(head);
    }
    k = end - 1;
  }
  return found;
}

TEST(GeneratedStructure, TheCheckerFindsLoopsAndBranches) {
  // The checker itself, on code that must fail it and code that must pass.
  EXPECT_EQ(forbiddenControlFlow("void f() { for (int i = 0; i < 3; ++i) { x(); } }").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("void f() { for (int j = 0; j < 30; ++j) { x(); } }").empty());
  EXPECT_EQ(forbiddenControlFlow("void f() { for (int j = 0; j < n; ++j) { x(); } }").size(), 1u);
  EXPECT_EQ(forbiddenControlFlow("void f() { if (a) { b(); } }").size(), 1u);
  EXPECT_EQ(forbiddenControlFlow("y = c ? 1.0 : 2.0;").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("  lambda = lambda != nullptr ? lambda : kNoMultipliers;\n").empty());
  EXPECT_EQ(forbiddenControlFlow("  lambda = lambda != nullptr ? lambda : other;\n").size(), 1u);
  EXPECT_EQ(forbiddenControlFlow("while (x) {}").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = 0; k < 324; ++k) dtau_dq[k] = Scalar(0);\n").empty());
  EXPECT_EQ(forbiddenControlFlow("  for (int k = 0; k < n; ++k) dtau_dq[k] = Scalar(0);\n").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = 117; k < 126; ++k) M[k] = 0.0;\n").empty());  // mass_matrix's zeros
  EXPECT_EQ(forbiddenControlFlow("  for (int k = a; k < 126; ++k) M[k] = 0.0;\n").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = 0; k < 18; ++k) w.fdd_h[k] = tau[k] - w.fdd_h[k];\n").empty());
  EXPECT_TRUE(forbiddenControlFlow("    for (int i = n - 1; i >= 0; --i) {\n    }\n").empty());
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = i + 1; k < n; ++k) {\n  }\n").empty());
  EXPECT_TRUE(forbiddenControlFlow("    for (int c = i; c < n; ++c) {\n    }\n").empty());  // S_K's rows
  EXPECT_TRUE(forbiddenControlFlow("    for (int c = 0; c <= i; ++c) {\n    }\n").empty());
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = 0; k < n * n; ++k) X[k] = Scalar(0);\n").empty());
  EXPECT_EQ(forbiddenControlFlow("  for (int k = 0; k < n * m; ++k) X[k] = Scalar(0);\n").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("  if constexpr (i < n) {\n  }\n").empty());
  EXPECT_EQ(forbiddenControlFlow("  if constexpr (i < w.n) {\n  }\n").size(), 1u);
  EXPECT_EQ(forbiddenControlFlow("  if (i < n) {\n  }\n").size(), 1u);
  EXPECT_GE(forbiddenControlFlow("  for (int k = 0; k < w.n; ++k) {\n  }\n").size(), 1u);
  EXPECT_GE(forbiddenControlFlow("  for (int i = 0; i < n; ++i) { x(); }\n").size(), 1u);
  EXPECT_GE(forbiddenControlFlow("  for (int k = 0; k < 18; ++k) w.h[k] = c ? a : b;\n").size(), 1u);
  EXPECT_GE(forbiddenControlFlow("  for (int k = 0; k < 18; ++k) { w.h[k] = 0; }\n").size(), 1u);
  EXPECT_EQ(forbiddenControlFlow("switch (t) { case 1: {} }").size(), 2u);
  EXPECT_TRUE(forbiddenControlFlow("  for (int k = 0; k < s.iterations; ++k) {\n    w.x = iff + format;\n  }").empty());
  EXPECT_TRUE(forbiddenControlFlow(stripComments("// if (a) for (;;)\nx = 1;")).empty());
  EXPECT_TRUE(forbiddenControlFlow(stripComments("#include \"a.hpp\"\n#pragma once\n")).empty());
  EXPECT_EQ(forbiddenControlFlow(stripComments("#define X 1\n")).size(), 1u);
}

// The pattern tables the sparse products' and the sweep's pairs' calls pass
// (`<name>_start`, `<name>_span`; `rows_q`, `rows_v`, `below`) that `code`
// does not declare `static constexpr int`: a table that is not a constant
// would let data decide a trip count.
std::vector<std::string> sparseTablesNotConstant(const std::string& code) {
  static const std::regex call(R"((?:sparse|world_frame)_\w+<[^>]*>\(([^;]*)\);)"),
      table(R"(\b(\w+_(start|span)|rows_[qv]|below)\b)");
  std::vector<std::string> found;
  for (auto c = std::sregex_iterator(code.begin(), code.end(), call); c != std::sregex_iterator(); ++c) {
    const std::string args = (*c)[1].str();
    for (auto t = std::sregex_iterator(args.begin(), args.end(), table); t != std::sregex_iterator(); ++t)
      if (code.find("static constexpr int " + t->str() + "[") == std::string::npos) found.push_back(t->str());
  }
  return found;
}

TEST(GeneratedStructure, TheCheckerFindsLoopsOverNonConstantTables) {
  EXPECT_TRUE(forbiddenControlFlow("    for (int j = start[r]; j < start[r + 1]; ++j) {\n    }\n").empty());
  EXPECT_TRUE(forbiddenControlFlow("      for (int k = span[2 * j]; k < span[2 * j + 1]; ++k) {\n      }\n").empty());
  EXPECT_GE(forbiddenControlFlow("    for (int j = start[r]; j < w.n[r]; ++j) {\n    }\n").size(), 1u);
  EXPECT_TRUE(forbiddenControlFlow("    for (int r = rows[2 * c]; r < rows[2 * c + 1]; ++r) {\n    }\n").empty());
  EXPECT_GE(forbiddenControlFlow("    for (int r = rows[2 * c]; r < span[2 * c + 1]; ++r) {\n    }\n").size(), 1u);
  const std::string call = "  sparse_right_product<2, 2, 2>(A, B, t_start, t_span, Scalar(-1), C);\n";
  EXPECT_EQ(sparseTablesNotConstant(call).size(), 2u);
  EXPECT_EQ(sparseTablesNotConstant("  static constexpr int t_start[3] = {0, 1, 2};\n" + call).size(), 1u);
  EXPECT_TRUE(sparseTablesNotConstant("  static constexpr int t_start[3] = {0, 1, 2};\n"
                                      "  static constexpr int t_span[4] = {0, 1, 1, 2};\n" + call)
                  .empty());
  const std::string pairs = "  world_frame_rows<2>(IS, BS, C, U, Scalar(-1), rows_q, dtau_dq);\n";
  EXPECT_EQ(sparseTablesNotConstant(pairs).size(), 1u);
  EXPECT_TRUE(sparseTablesNotConstant("  static constexpr int rows_q[4] = {0, 2, 1, 2};\n" + pairs).empty());
}

TEST(GeneratedStructure, TheSparseProductsReadConstantTables) {
  const std::vector<std::string> sources = split(PROXGEN_GENERATED_SOURCES, '|');
  ASSERT_FALSE(sources.empty());
  for (const std::string& path : sources)
    for (const std::string& t : sparseTablesNotConstant(stripComments(readFile(path))))
      ADD_FAILURE() << path << ": the table " << t << " is not a static constexpr int array";
}

TEST(GeneratedStructure, OnlyTheIterationLoopsLoopOrBranch) {
  const std::vector<std::string> sources = split(PROXGEN_GENERATED_SOURCES, '|');
  ASSERT_FALSE(sources.empty());
  for (const std::string& path : sources) {
    const std::string code = stripComments(readFile(path));
    ASSERT_FALSE(code.empty()) << path;
    for (const std::string& f : forbiddenControlFlow(code)) ADD_FAILURE() << path << ": " << f;
  }
}

// Symbols of a static library, one name per line (nm -C: demangled).
// The heads of the functions of `code` whose bodies hold no statement but
// `static_cast<void>(param);` lines (function bodies start after ") noexcept {"
// at the end of a line and end at a "}" alone at column 0).
std::vector<std::string> emptyFunctions(const std::string& code) {
  static const std::regex unused(R"(\s*static_cast<void>\(\w+\);\s*)");
  std::vector<std::string> found;
  std::istringstream in(code);
  std::string line, head;
  bool inside = false, empty = true;
  while (std::getline(in, line)) {
    const std::string open = ") noexcept {";
    if (!inside && line.size() >= open.size() && line.compare(line.size() - open.size(), open.size(), open) == 0) {
      inside = true, empty = true, head = line;
      continue;
    }
    if (!inside) continue;
    if (line == "}") {
      if (empty) found.push_back(head);
      inside = false;
    } else if (!std::regex_match(line, unused) && line.find_first_not_of(' ') != std::string::npos) {
      empty = false;
    }
  }
  return found;
}

TEST(GeneratedStructure, TheCheckerFindsEmptyFunctions) {
  EXPECT_EQ(emptyFunctions("void f(int a) noexcept {\n  static_cast<void>(a);\n}\n").size(), 1u);
  EXPECT_EQ(emptyFunctions("void f() noexcept {\n}\n").size(), 1u);
  EXPECT_TRUE(emptyFunctions("void f(int a) noexcept {\n  static_cast<void>(a);\n  w.x = 1.0;\n}\n").empty());
}

TEST(GeneratedStructure, NoEmptyFunctions) {
  const std::vector<std::string> sources = split(PROXGEN_GENERATED_SOURCES, '|');
  ASSERT_FALSE(sources.empty());
  for (const std::string& path : sources)
    for (const std::string& f : emptyFunctions(stripComments(readFile(path)))) ADD_FAILURE() << path << ": empty " << f;
}

std::vector<std::string> symbols(const std::string& library) {
  std::vector<std::string> out;
  const std::string cmd = std::string(PROXGEN_NM) + " -C '" + library + "' 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char line[4096];
  while (std::fgets(line, sizeof line, p)) {
    std::string l(line);
    while (!l.empty() && (l.back() == '\n' || l.back() == '\r')) l.pop_back();
    // "<value> <type> <name>" or "<blank> U <name>": the name follows the type letter.
    if (l.size() > 19 && l[17] != ' ' && l[18] == ' ') out.push_back(l.substr(19));
  }
  pclose(p);
  return out;
}

bool forbiddenSymbol(const std::string& s) {
  for (const char* exact : {"malloc", "calloc", "realloc", "free", "aligned_alloc", "posix_memalign", "memalign"})
    if (s == exact) return true;
  for (const char* prefix : {"operator new", "operator delete"})
    if (s.rfind(prefix, 0) == 0) return true;
  for (const char* part : {"__cxa_throw", "__cxa_allocate_exception", "__cxa_begin_catch", "__gxx_personality", "_Unwind_"})
    if (s.find(part) != std::string::npos) return true;
  return false;
}

TEST(GeneratedStructure, ObjectsUseNoHeapAndNoExceptions) {
  EXPECT_TRUE(forbiddenSymbol("malloc") && forbiddenSymbol("operator new(unsigned long)") &&
              forbiddenSymbol("__gxx_personality_v0") && forbiddenSymbol("_Unwind_Resume"));
  EXPECT_FALSE(forbiddenSymbol("arm::(anonymous namespace)::accelerate_free_bodies(arm::Workspace&)"));
  const std::vector<std::string> libraries = split(PROXGEN_GENERATED_LIBRARIES, '|');
  ASSERT_FALSE(libraries.empty());
  for (const std::string& lib : libraries) {
    const std::vector<std::string> syms = symbols(lib);
    bool entry = false;  // nm really listed this solver: an entry point is there (a solver may hold only mass_matrix)
    for (const std::string& s : syms) {
      for (const char* name : {"::constrained_aba(", "::prox_pv(", "::mass_matrix("})
        entry |= s.find(name) != std::string::npos;
      if (forbiddenSymbol(s)) ADD_FAILURE() << lib << " references " << s;
    }
    EXPECT_TRUE(entry) << "nm found no entry point in " << lib;
  }
}

}  // namespace

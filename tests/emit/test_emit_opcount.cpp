// The operation count in the banner of a generated file (counted by the
// emitter from its expression graph: CodeBuilder::opCount) against an
// independent count of the printed source: a small lexer that reads the
// function bodies, counts the operator tokens and the runtime calls, follows
// the calls into the functions they name, and multiplies loop bodies by their
// trip count. The two share nothing but the file, so a count that misses a
// kind of statement, a part function, a loop or a sign fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <regex>
#include <sstream>

#include "cases/cases.hpp"
#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// add/sub, mul, div, neg, sqrt, sincos, log6: the banner's order.
constexpr int kKinds = 7;
using Counts = std::array<long, kKinds>;
const char* const kKindNames[kKinds] = {"add/sub", "mul", "div", "neg", "sqrt", "sincos", "log6"};

// once + K perK
struct Poly {
  Counts once{}, perK{};
};

void addTo(Poly& a, const Poly& b, long k = 1) {
  for (int i = 0; i < kKinds; ++i) {
    a.once[std::size_t(i)] += k * b.once[std::size_t(i)];
    a.perK[std::size_t(i)] += k * b.perK[std::size_t(i)];
  }
}

struct Token {
  enum Kind { Ident, Number, Punct } kind;
  std::string text;
};

// The tokens of one statement line; the contents of [...] (integer index
// arithmetic, `[r][c + j]`) are left out: they compute no Scalar.
std::vector<Token> lex(const std::string& line) {
  std::vector<Token> out;
  int brackets = 0;
  for (std::size_t i = 0; i < line.size();) {
    const char c = line[i];
    if (c == '/' && i + 1 < line.size() && line[i + 1] == '/') break;  // comment
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (c == '[' || c == ']') {
      brackets += c == '[' ? 1 : -1;
      ++i;
      continue;
    }
    std::size_t j = i;
    Token::Kind kind = Token::Punct;
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      kind = Token::Ident;  // w.KA_x, proxgen_rt::sincos, s.mu: one token
      while (j < line.size() && (std::isalnum(static_cast<unsigned char>(line[j])) || line[j] == '_' || line[j] == '.' ||
                                 line[j] == ':'))
        ++j;
    } else if (std::isdigit(static_cast<unsigned char>(c)) ||
               (c == '.' && i + 1 < line.size() && std::isdigit(static_cast<unsigned char>(line[i + 1])))) {
      kind = Token::Number;  // 5.421010862427522e-20, 0.5f
      while (j < line.size() && (std::isdigit(static_cast<unsigned char>(line[j])) || line[j] == '.')) ++j;
      if (j < line.size() && (line[j] == 'e' || line[j] == 'E')) {
        ++j;
        if (j < line.size() && (line[j] == '+' || line[j] == '-')) ++j;
        while (j < line.size() && std::isdigit(static_cast<unsigned char>(line[j]))) ++j;
      }
      if (j < line.size() && line[j] == 'f') ++j;
    } else {
      j = i + 1;
    }
    if (brackets == 0) out.push_back({kind, line.substr(i, j - i)});
    i = j;
  }
  return out;
}

struct Source {
  std::map<std::string, std::vector<std::string>> bodies;  // function name -> its body lines
  std::map<std::string, Poly> memo;
};

// Every `void name(...) noexcept {` at column 0 up to its closing `}` line.
Source functions(const std::string& text) {
  Source src;
  std::istringstream in(text);
  std::string line, name;
  bool inHead = false, inBody = false;
  static const std::regex head(R"(^(PROXGEN_RT_NOINLINE )?void (\w+)\()");
  while (std::getline(in, line)) {
    std::smatch m;
    if (!inHead && !inBody && std::regex_search(line, m, head)) {
      name = m[2].str();
      inHead = true;
    }
    if (inHead) {
      if (!line.empty() && line.back() == '{') {
        inHead = false;
        inBody = true;
        src.bodies[name];
      }
      continue;
    }
    if (inBody) {
      if (line == "}") inBody = false;
      else src.bodies[name].push_back(line);
    }
  }
  return src;
}

Poly count(Source& src, const std::string& fn);

// One statement line: its operator tokens and calls. `flips`: a signed
// pair's turns of one lane (proxgen_rt::flip, docs/emitter.md, "Mirrored
// blocks: signed pairs") that stand for one block's negation: at a term's
// start one block negated where the other did not (one negation, whichever
// lane); after a `+` one block subtracted where the other added, which the `+`
// already counts for both lanes.
Poly countLine(Source& src, const std::string& line, long* flips = nullptr) {
  Poly p;
  const std::vector<Token> t = lex(line);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::string& x = t[k].text;
    const bool prevValue =
        k > 0 && (t[k - 1].kind != Token::Punct || t[k - 1].text == ")");  // an operand ends before this token
    if (t[k].kind == Token::Punct && (x == "+" || x == "-")) {
      if (prevValue) ++p.once[0];
      else if (x == "-" && !(k + 1 < t.size() && t[k + 1].kind == Token::Number)) ++p.once[3];  // -literal: a literal
      else if (x == "+") ADD_FAILURE() << "unary + in: " << line;
    } else if (x == "*") {
      ++p.once[1];
    } else if (x == "/") {
      ++p.once[2];
    } else if (t[k].kind == Token::Ident && k + 1 < t.size() && t[k + 1].text == "(") {
      if (x == "std::sqrt") ++p.once[4];
      else if (x == "proxgen_rt::sincos_joint" || x == "proxgen_rt::sincos_joint_called") ++p.once[5];
      else if (x == "proxgen_rt::log6") ++p.once[6];
      else if (x == "proxgen_rt::largest_magnitude") continue;  // compares and selects: no counted arithmetic
      else if (x == "proxgen_rt::gather2" || x == "proxgen_rt::pair_at") continue;  // a pair's loads: no arithmetic
      else if (x == "proxgen_rt::flip") {
        if (!flips) ADD_FAILURE() << "a flip outside a paired kernel: " << line;
        else if (!(k > 0 && t[k - 1].kind == Token::Punct && t[k - 1].text == "+")) ++*flips;
      }
      else if (src.bodies.count(x)) addTo(p, count(src, x));
      else if (x != "Scalar") ADD_FAILURE() << "a call the count does not know: " << x << " in: " << line;
    }
  }
  return p;
}

// A function body: blocks nest by their braces; `for (int k = A; k < N; ++k) {`
// (or <=; after PROXGEN_RT_NO_UNROLL, the column loops) multiplies its body by
// N - A (+1), N a literal or s.iterations = K;
// `for (int k = A; k < N; ++k) statement;` (mass_matrix's runs of zeros)
// multiplies the statement by N - A.
Poly count(Source& src, const std::string& fn) {
  if (src.memo.count(fn)) return src.memo[fn];
  static const std::regex loop(
      R"(^(?:PROXGEN_RT_NO_UNROLL )?for \(int (\w+) = (\d+); \1 (<=?) (\d+|s\.iterations); \+\+\1\) \{$)");
  static const std::regex oneLine(R"(^for \(int k = (\d+); k < (\d+); \+\+k\) ([^{}]+;)$)");
  struct Frame {
    Poly p;
    long trips = 1;
    bool onK = false;
  };
  std::vector<Frame> stack(1);
  for (const std::string& raw : src.bodies.at(fn)) {
    const std::size_t first = raw.find_first_not_of(' ');
    if (first == std::string::npos) continue;
    const std::string line = raw.substr(first);
    if (line.rfind("//", 0) == 0) continue;
    if (line == "}") {
      const Frame f = stack.back();
      stack.pop_back();
      Poly& out = stack.back().p;
      addTo(out, f.p, f.trips);
      if (f.onK) {
        for (int i = 0; i < kKinds; ++i) {
          EXPECT_EQ(f.p.perK[std::size_t(i)], 0) << "a loop on K inside another in " << fn;
          out.perK[std::size_t(i)] += f.p.once[std::size_t(i)];
        }
      }
      continue;
    }
    if (line.back() == '{') {
      Frame f;
      std::smatch m;
      if (line.rfind("for", 0) == 0 || line.rfind("PROXGEN_RT_NO_UNROLL", 0) == 0) {
        if (!std::regex_match(line, m, loop)) {
          ADD_FAILURE() << "a loop the count cannot read: " << line;
        } else {
          f.onK = m[4].str() == "s.iterations";
          f.trips = (f.onK ? 0 : std::stol(m[4].str())) - std::stol(m[2].str()) + (m[3].str() == "<=" ? 1 : 0);
        }
      } else {
        EXPECT_EQ(line, "{") << "a block the count cannot read";
      }
      stack.push_back(f);
      continue;
    }
    std::smatch one;
    if (std::regex_match(line, one, oneLine)) {  // a fill over literal bounds: its statement N - A times
      addTo(stack.back().p, countLine(src, one[3].str()), std::stol(one[2].str()) - std::stol(one[1].str()));
      continue;
    }
    // A paired kernel (shared_<k>_x2) runs two blocks in the lanes of a pair:
    // each operation twice; a call statement (sincos) is printed per lane.
    const bool paired = fn.size() > 3 && fn.compare(fn.size() - 3, 3, "_x2") == 0;
    long flips = 0;
    addTo(stack.back().p, countLine(src, line, paired ? &flips : nullptr),
          paired && line.rfind("proxgen_rt::sincos", 0) != 0 ? 2 : 1);
    stack.back().p.once[3] += flips;  // one block's negation each, not two
  }
  EXPECT_EQ(stack.size(), 1u) << "unbalanced braces in " << fn;
  src.memo[fn] = stack[0].p;
  return stack[0].p;
}

// "a" or "a + b K" -> (a, b)
std::pair<long, long> affine(const std::string& s) {
  static const std::regex re(R"(^(\d+)(?: \+ (\d+) K)?$)");
  std::smatch m;
  if (!std::regex_match(s, m, re)) {
    ADD_FAILURE() << "not a count: '" << s << "'";
    return {-1, -1};
  }
  return {std::stol(m[1].str()), m[2].matched ? std::stol(m[2].str()) : 0};
}

// The banner's two lines of one entry point.
Poly banner(const std::string& text, const std::string& fn, long* totalAtDefault) {
  Poly p;
  const std::regex head("//   " + fn + R"(: ([^(]*) \(= (\d+) at K = \d+\)\n//     (.*)\n)");
  std::smatch m;
  if (!std::regex_search(text, m, head)) {
    ADD_FAILURE() << "no operation count of " << fn << " in the banner";
    return p;
  }
  *totalAtDefault = std::stol(m[2].str());
  std::string fields = m[3].str();
  for (int i = 0; i < kKinds; ++i) {
    const std::string key = std::string(kKindNames[i]) + " ";
    const std::size_t at = fields.find(key);
    if (at == std::string::npos) {
      ADD_FAILURE() << "no '" << key << "' in " << fields;
      continue;
    }
    const std::size_t end = fields.find(',', at);
    const auto [a, b] = affine(fields.substr(at + key.size(), end == std::string::npos ? end : end - at - key.size()));
    p.once[std::size_t(i)] = a;
    p.perK[std::size_t(i)] = b;
  }
  return p;
}

void expectCountsMatch(const SolverFiles& f, const std::string& what, int K,
                       const std::vector<std::string>& entries = {"constrained_aba", "prox_pv"}) {
  Source src = functions(f.source);
  for (const std::string& fn : entries) ASSERT_TRUE(src.bodies.count(fn)) << what << " " << fn;
  for (const std::string& fn : entries) {
    long total = -1;
    const Poly b = banner(f.source, fn, &total);
    const Poly c = count(src, fn);
    long sum = 0;
    for (int i = 0; i < kKinds; ++i) {
      EXPECT_EQ(b.once[std::size_t(i)], c.once[std::size_t(i)]) << what << " " << fn << " " << kKindNames[i] << " once";
      EXPECT_EQ(b.perK[std::size_t(i)], c.perK[std::size_t(i)]) << what << " " << fn << " " << kKindNames[i] << " per K";
      sum += c.once[std::size_t(i)] + K * c.perK[std::size_t(i)];
    }
    EXPECT_EQ(total, sum) << what << " " << fn << ": the total at the default K";
    // Every solver multiplies: a count of zero would mean the lexer read nothing.
    EXPECT_GT(c.once[1], 0) << what << " " << fn;
  }
  EXPECT_NE(f.header.find("//   prox_pv: "), std::string::npos) << "the header has the same banner";
}

GenerateOptions example(const std::string& robot, const std::string& layout = "") {
  GenerateOptions g;
  const std::string dir = test::sourceDir() + "/generated/" + robot;
  g.urdf = dir + "/" + robot + ".urdf";
  g.layout = layout.empty() ? dir + "/layout.yaml" : layout;
  g.name = robot;
  return g;
}

TEST(OperationCount, TheLexerReadsWhatItShould) {
  // The lexer's own rules, on lines of the shapes the emitter prints.
  Source src;
  Poly p = countLine(src, "w.x[2][3 + j] = -w.a[1] + 5.421010862427522e-20*w.b[0] - 0.5f*t0*t1;");
  EXPECT_EQ(p.once, (Counts{2, 3, 0, 1, 0, 0, 0}));  // + and -; three *; the leading -
  p = countLine(src, "const Scalar t0 = -1.5*(w.a - w.b);");
  EXPECT_EQ(p.once, (Counts{1, 1, 0, 0, 0, 0, 0}));  // -1.5 is a literal
  p = countLine(src, "const Scalar r0 = std::sqrt(t3); proxgen_rt::sincos_joint(q[0], w.sq[0], w.cq[0]); x = 1.0 / r0;");
  EXPECT_EQ(p.once, (Counts{0, 0, 1, 0, 1, 1, 0}));
  // A signed pair's flips: at a term's start one block's negation, after a + nothing (the + counts).
  long flips = 0;
  p = countLine(src, "const ScalarPair x0 = proxgen_rt::flip(proxgen_rt::pair_at(k, 2), a*b) + "
                     "proxgen_rt::flip(proxgen_rt::pair_at(k, 3), c);", &flips);
  EXPECT_EQ(p.once, (Counts{1, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(flips, 1);
}

TEST(OperationCount, TheBannerCountsWhatTheExamplesCompute) {
  for (const char* robot : {"arm", "quadruped", "humanoid"})
    for (ScalarType t : {ScalarType::Double, ScalarType::Float}) {
      GenerateOptions g = example(robot);
      g.scalar = t;
      expectCountsMatch(generateFiles(g), robot, 3);
    }
}

TEST(OperationCount, WithGainsTheLogarithmCounts) {
  // kp on a weld: the runtime's log6 (one per weld), and more arithmetic.
  const SolverFiles f = generateFiles(example("arm", test::sourceDir() + "/tests/generated/layouts/arm_gains.yaml"));
  expectCountsMatch(f, "arm_gains", 2);  // the layout sets iterations: 2
  EXPECT_NE(f.source.find("log6 1\n"), std::string::npos) << "the arm's one weld with kp: one log6 per call";
}

TEST(OperationCount, TheJointSpaceFunctionsCountWhatTheyCompute) {
  // inverse_dynamics (with its nullptr select), nonlinear_effects, mass_matrix, mass_matrix_inverse,
  // each with the helper it calls (kinematics, joint_transforms).
  const std::vector<std::string> entries = {"inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse"};
  for (const char* robot : {"arm", "quadruped"}) {
    GenerateOptions g = example(robot);
    g.functions = "constrained_aba,prox_pv,inverse_dynamics,nonlinear_effects,mass_matrix,mass_matrix_inverse";
    expectCountsMatch(generateFiles(g), robot, 3, entries);
  }
}

TEST(OperationCount, MassMatrixInverseCodeGrowsLinearly) {
  // Its passes loop over runs of columns (docs/dynamics.md, "Column loops"):
  // twice the chain, about twice the code. Unrolled per column, the forward
  // pass alone is n^2 / 2 column blocks: 4x the code for 2x the chain.
  std::vector<std::size_t> lines;
  for (int links : {12, 24}) {
    const test::TempFile urdf(".urdf"), layout(".yaml");
    urdf.write(test::syntheticTreeUrdf(links, 1));
    layout.write("base: fixed\nconstraints: []\n");
    GenerateOptions g;
    g.urdf = urdf.path();
    g.layout = layout.path();
    g.name = "chain";
    g.functions = "mass_matrix_inverse";
    const SolverFiles f = generateFiles(g);
    lines.push_back(std::size_t(std::count(f.source.begin(), f.source.end(), '\n')));
    EXPECT_NE(f.source.find("for (int j = 0; j < "), std::string::npos) << links << " links: no column loop";
  }
  EXPECT_LT(double(lines[1]) / double(lines[0]), 2.5) << lines[0] << " -> " << lines[1] << " lines";
}

TEST(OperationCount, SharedCases) {
  PROXGEN_REQUIRE_MODELS();
  for (const char* name : {"iiwa_h3", "solo_f3x4"}) {
    expectCountsMatch(generateCase(test::modelPath("cases.yaml"), name, "", ScalarType::Double), name, 3);
  }
  // The Atlas' arms turn about negated axes: its mirrored blocks run as signed
  // pairs, whose flips the count reads as the one block's negation.
  const SolverFiles atlas = generateCase(test::modelPath("cases.yaml"), "atlas_shadow_f6x2", "", ScalarType::Double);
  EXPECT_GT(test::occurrences(atlas.source, "proxgen_rt::flip("), 0);
  EXPECT_GT(test::occurrences(atlas.source, " in pairs, mirrored: "), 0) << "the banner names the signed pairs";
  expectCountsMatch(atlas, "atlas_shadow_f6x2", 3);
}

}  // namespace
}  // namespace proxgen::emit

// URDF + layout text -> the two files of a generated solver (generator/emit).
// Input: the URDF, a line "---8<---", then the layout; without the marker the
// whole input is the URDF and the layout welds its last link. Checks what the
// emitter promises about its text whatever the names and numbers are
// (docs/design.md, "Bad input"): printable ASCII only, no trigraph,
// no block-comment token, no line splice, no preprocessor line other than the
// ones every solver has, and code (outside comments and those lines) made of
// identifiers, numbers, operators and string literals of escaped names only
// (no raw quote, backslash, '#', '?' or other character a raw name would
// bring along). The same bytes on a second run.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <string_view>

#include "emit/emitter.hpp"
#include "emit/plan.hpp"
#include "fuzz_common.hpp"
#include "model/layout.hpp"
#include "model/urdf.hpp"

namespace {

using proxgen::fuzz::broken;

// Emission time grows with the tree and the rows; bigger inputs add nothing
// the loaders' fuzzing does not already cover.
constexpr int kMaxDofs = 24, kMaxRows = 24;
const char* const kMarker = "\n---8<---\n";

proxgen::emit::SolverFiles emit(const proxgen::System& sys) {
  const proxgen::emit::Plan plan = proxgen::emit::makePlan(sys, "fuzz", proxgen::emit::ScalarType::Double);
  proxgen::emit::SolverInputs inputs;
  inputs.urdfName = "fuzz.urdf";
  inputs.urdfSha256 = "0";
  inputs.layoutName = "fuzz.yaml";
  inputs.layoutSha256 = "0";
  return proxgen::emit::emitSolver(sys, plan, inputs);
}

std::set<std::string> preprocessorLines(const std::string& text) {
  std::set<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && line[first] == '#') out.insert(line);
  }
  return out;
}

// The preprocessor lines of a solver for an ordinary robot: the only ones allowed.
const std::set<std::string>& allowedDirectives() {
  static const std::set<std::string> lines = [] {
    proxgen::Layout layout = proxgen::loadLayout(PROXGEN_FUZZ_DATA_DIR "/good/arm3_tool.yaml");
    const proxgen::System sys = proxgen::bindLayout(proxgen::loadUrdf(PROXGEN_FUZZ_DATA_DIR "/good/arm3.urdf", false), layout);
    const proxgen::emit::SolverFiles f = emit(sys);
    std::set<std::string> all = preprocessorLines(f.header);
    for (const std::string& l : preprocessorLines(f.source)) all.insert(l);
    return all;
  }();
  return lines;
}

// A line's code: without its // comment and its string literals (the
// header's name arrays hold the raw names as emit::cStringLiteral writes
// them). A literal must hold only printable characters other than '"', a
// backslash and '?', and the escapes of a quote, a backslash, '?' and \ooo.
std::string withoutStringLiterals(const std::string& line) {
  std::string out;
  for (std::size_t k = 0; k < line.size(); ++k) {
    if (line.compare(k, 2, "//") == 0) break;
    if (line[k] != '"') {
      out += line[k];
      continue;
    }
    for (++k; k < line.size() && line[k] != '"'; ++k) {
      if (line[k] == '?') broken("unescaped '?' in a string literal", line);
      if (line[k] != '\\') continue;
      const bool simple = k + 1 < line.size() && std::string_view("\"\\?").find(line[k + 1]) != std::string_view::npos;
      bool octal = k + 3 < line.size();
      for (std::size_t j = 1; j <= 3 && octal; ++j) octal = line[k + j] >= '0' && line[k + j] <= '7';
      if (!simple && !octal) broken("unknown escape in a string literal", line);
      k += simple ? 1 : 3;
    }
    if (k >= line.size()) broken("unterminated string literal", line);
    out += "s";
  }
  return out;
}

/// The text outside // comments, preprocessor lines and string literals.
std::string codeOf(const std::string& text) {
  std::string code;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && line[first] == '#') continue;
    code += withoutStringLiterals(line) + "\n";
  }
  return code;
}

// What C++ code made of identifiers, numeric literals and operators needs. Not
// in it: quotes, backslash, '#', '?', '$', '@', '`' (string and character
// literals, escapes, directives, trigraphs): the characters a raw URDF name
// would most likely bring, so a name printed outside a comment shows up here.
bool codeCharacter(unsigned char c) {
  return std::isalnum(c) || std::string_view("_ \n()[]{};,.+-*/=<>&|!~^%:").find(char(c)) != std::string_view::npos;
}

void checkText(const std::string& text, const std::string& code) {
  for (unsigned char c : text)
    if (c != '\n' && (c < 0x20 || c > 0x7e)) broken("byte outside printable ASCII in generated text", std::to_string(c));
  if (text.find("??") != std::string::npos) broken("trigraph sequence in generated text", "");
  if (text.find("/*") != std::string::npos || text.find("*/") != std::string::npos)
    broken("block comment token in generated text", "");
  if (text.find("\\\n") != std::string::npos) broken("line splice in generated text", "");
  for (const std::string& line : preprocessorLines(text))
    if (!allowedDirectives().count(line)) broken("unexpected preprocessor line", line);
  for (std::size_t k = 0; k < code.size(); ++k)
    if (!codeCharacter(static_cast<unsigned char>(code[k])))
      broken("character outside code syntax in generated code", code.substr(k < 80 ? 0 : k - 80, 160));
}

void run(const std::string& urdf, const std::string* yaml) {
  for (bool floating : {false, true}) {
    proxgen::Layout layout;
    if (yaml) {
      layout = proxgen::parseLayout(*yaml, "fuzz.yaml");
      if (layout.floatingBase != floating) continue;
    } else {
      layout.floatingBase = floating;
    }
    proxgen::Model model = proxgen::parseUrdf(urdf, "fuzz.urdf", floating);
    if (model.nv > kMaxDofs) return;
    if (!yaml && model.frames.size() > 1) {
      proxgen::Constraint c;
      c.name = model.frames.back().name;  // a URDF name as a constraint name too
      c.link = model.frames.back().name;
      layout.constraints.push_back(c);
    }
    const proxgen::System sys = proxgen::bindLayout(std::move(model), layout);
    if (sys.nc > kMaxRows) return;
    const proxgen::emit::SolverFiles a = emit(sys), b = emit(sys);
    if (a.header != b.header || a.source != b.source) broken("emission is not deterministic", "");
    checkText(a.header, codeOf(a.header));
    checkText(a.source, codeOf(a.source));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  allowedDirectives();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = input.find(kMarker);
  const std::string urdf = input.substr(0, cut);
  const std::string yaml = cut == std::string::npos ? "" : input.substr(cut + std::string(kMarker).size());
  PROXGEN_FUZZ_GUARD(run(urdf, cut == std::string::npos ? nullptr : &yaml));
  return 0;
}

#include "emit/identifiers.hpp"

#include <fmt/format.h>

#include <array>
#include <cctype>

namespace proxgen::emit {
namespace {

// C++17 keywords and alternative tokens, C++20 keywords (so the files stay
// valid in later standards), the standard macros the runtime's <cmath> may
// define, and the namespaces the generated files use.
constexpr std::array kReserved = {
    "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break", "case",
    "catch", "char", "char8_t", "char16_t", "char32_t", "class", "compl", "concept", "const", "consteval",
    "constexpr", "constinit", "const_cast", "continue", "co_await", "co_return", "co_yield", "decltype",
    "default", "delete", "do", "double", "dynamic_cast", "else", "enum", "explicit", "export", "extern",
    "false", "float", "for", "friend", "goto", "if", "inline", "int", "long", "mutable", "namespace", "new",
    "noexcept", "not", "not_eq", "nullptr", "operator", "or", "or_eq", "private", "protected", "public",
    "register", "reinterpret_cast", "requires", "return", "short", "signed", "sizeof", "static",
    "static_assert", "static_cast", "struct", "switch", "template", "this", "thread_local", "throw", "true",
    "try", "typedef", "typeid", "typename", "union", "unsigned", "using", "virtual", "void", "volatile",
    "wchar_t", "while", "xor", "xor_eq", "final", "override", "import", "module",
    // macros of <cmath>, <cstddef>, <cassert>, <cerrno>, <climits>
    "NULL", "EOF", "assert", "errno", "offsetof", "INFINITY", "NAN", "HUGE_VAL", "HUGE_VALF", "HUGE_VALL",
    "FP_NAN", "FP_INFINITE", "FP_ZERO", "FP_NORMAL", "FP_SUBNORMAL", "FP_FAST_FMA", "FP_ILOGB0",
    "FP_ILOGBNAN", "MATH_ERRNO", "MATH_ERREXCEPT", "math_errhandling", "isnan", "isinf", "isfinite",
    "signbit", "fpclassify", "isnormal", "EDOM", "ERANGE", "EILSEQ", "CHAR_BIT", "INT_MAX", "INT_MIN",
    "M_PI", "M_E", "unix", "linux", "i386",
    // namespaces and names the generated files rely on
    "std", "proxgen", "proxgen_rt", "Scalar", "Settings", "Workspace", "main"};

bool isIdentChar(unsigned char c) { return std::isalnum(c) != 0 && c < 0x80; }

}  // namespace

bool isReservedIdentifier(const std::string& id) {
  for (const char* r : kReserved)
    if (id == r) return true;
  return false;
}

std::string sanitizeIdentifier(const std::string& name) {
  // Every run of characters that are not ASCII letters or digits becomes one
  // underscore; underscores at either end are dropped.
  std::string out;
  for (unsigned char c : name) {
    if (isIdentChar(c)) out += char(c);
    else if (!out.empty() && out.back() != '_') out += '_';
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (out.empty()) out = "unnamed";
  if (std::isdigit(static_cast<unsigned char>(out[0]))) out = "n" + out;
  if (out.size() > kMaxIdentifierLength) {
    out.resize(kMaxIdentifierLength);
    while (out.back() == '_') out.pop_back();
  }
  if (isReservedIdentifier(out)) out = "kw_" + out;
  return out;
}

std::string IdentifierSet::make(const std::string& name, int index) {
  std::string id = sanitizeIdentifier(name);
  if (taken_.count(id)) id = fmt::format("{}_{}", id, index);
  // A name that already ended in "_<index>" can still collide; count upwards.
  for (int k = 2; taken_.count(id); ++k) id = fmt::format("{}_{}_{}", sanitizeIdentifier(name), index, k);
  taken_.insert(id);
  return id;
}

std::string escapeComment(const std::string& text) {
  std::string out;
  std::size_t shown = 0;
  char prev = 0;
  for (unsigned char c : text) {
    if (shown == kMaxCommentLength) {
      out += fmt::format("... ({} bytes)", text.size());
      return out;
    }
    const bool printable = c >= 0x20 && c < 0x7f;
    // "*/" would close a block comment, "/*" opens one (-Wcomment), "??" may
    // start a trigraph, a backslash may splice the next line into the comment.
    const bool breaksComment = (c == '/' && prev == '*') || (c == '*' && prev == '/') ||
                               (c == '?' && prev == '?') || c == '\\';
    if (!printable || breaksComment) {
      out += fmt::format("\\x{:02x}", c);
      prev = 0;
    } else {
      out += char(c);
      prev = char(c);
    }
    ++shown;
  }
  return out;
}

}  // namespace proxgen::emit

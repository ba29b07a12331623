#include "emit/identifiers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <iterator>

namespace proxgen::emit {
namespace {

// C++17 keywords and alternative tokens, C++20 keywords (so the files stay
// valid in later standards), and the names the generated files themselves use
// or that common headers outside the standard library define as macros.
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
    // predefined on some targets, and macros of common non-standard headers
    // (windows.h, sys/param.h, Eigen's namespace)
    "unix", "linux", "i386", "min", "max", "MIN", "MAX", "TRUE", "FALSE", "ERROR", "DELETE", "IN", "OUT",
    "OPTIONAL", "interface", "near", "far", "pascal", "cdecl", "small", "Eigen", "noreturn", "complex",
    "imaginary", "I",
    // namespaces and names the generated files rely on
    "std", "proxgen", "proxgen_rt", "Scalar", "Settings", "Workspace", "main"};

// The global names and macros of the C and C++ libraries (reserved_names.inc:
// derived by the compiler from the headers, kept honest by a test).
constexpr const char* kLibraryNames[] = {
#include "emit/reserved_names.inc"
};

// Families the C and POSIX standards reserve for the library, so that a name of
// one is taken on some platform even where this list's headers lack it:
// POSIX types end in "_t"; errno macros are E + digit or capital; and the
// macro prefixes of <cmath>, <cfloat>, <climits>, <cstdint>, <cinttypes>,
// <cfenv>, <csignal>, <clocale>, <fcntl.h> and <sys/stat.h>.
bool inReservedFamily(const std::string& id) {
  const auto starts = [&](const char* p) { return id.rfind(p, 0) == 0; };
  const auto upperAt = [&](std::size_t k) {
    return id.size() > k && (std::isupper(static_cast<unsigned char>(id[k])) || std::isdigit(static_cast<unsigned char>(id[k])));
  };
  if (id.size() > 2 && id.compare(id.size() - 2, 2, "_t") == 0) return true;
  if (id[0] == 'E' && upperAt(1)) return true;
  for (const char* p : {"M_", "FP_", "FLT_", "DBL_", "LDBL_", "FE_", "SIG_", "LC_", "O_", "S_I", "F_", "AT_",
                        "MATH_", "HUGE_", "SIZE_", "PTRDIFF_", "WCHAR_", "WINT_", "SCHAR_", "UCHAR_", "CHAR_",
                        "SHRT_", "USHRT_", "LONG_", "ULONG_", "LLONG_", "ULLONG_", "EXIT_", "SEEK_"})
    if (starts(p)) return true;
  // SIGINT, PRId64, SCNx32, INT8_MAX, UINTMAX_MAX, INT_FAST16_MIN
  if ((starts("SIG") && upperAt(3)) || (starts("PRI") && id.size() > 3 && std::islower(static_cast<unsigned char>(id[3]))) ||
      (starts("SCN") && id.size() > 3 && std::islower(static_cast<unsigned char>(id[3]))))
    return true;
  if ((starts("INT") && upperAt(3)) || (starts("UINT") && upperAt(4)) || starts("INT_") || starts("UINT_")) return true;
  return false;
}

bool isIdentChar(unsigned char c) { return std::isalnum(c) != 0 && c < 0x80; }

}  // namespace

bool isReservedIdentifier(const std::string& id) {
  // The prefix sanitizeIdentifier gives reserved names is ours: no library
  // declares a name starting "kw_", so "kw_size_t" is free although it ends in "_t".
  if (id.empty() || id.rfind("kw_", 0) == 0) return false;
  for (const char* r : kReserved)
    if (id == r) return true;
  const auto less = [](const char* a, const char* b) { return std::strcmp(a, b) < 0; };
  if (std::binary_search(std::begin(kLibraryNames), std::end(kLibraryNames), id.c_str(), less)) return true;
  return inReservedFamily(id);
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
  if (isReservedIdentifier(out)) {
    // The prefix counts against the length too (a 48-character "FP_..." is a
    // reserved family); "kw_..." is never reserved, so cutting keeps it free.
    out = "kw_" + out;
    if (out.size() > kMaxIdentifierLength) {
      out.resize(kMaxIdentifierLength);
      while (out.back() == '_') out.pop_back();
    }
  }
  return out;
}

std::string IdentifierSet::make(const std::string& name, int index) {
  const std::string stem = sanitizeIdentifier(name);
  // A suffixed name can fall into a reserved family ("M" taken, "M_2" is one of
  // M_*: fuzz_identifiers found it); the prefix makes it free, as for a stem.
  const auto free = [](const std::string& id) { return isReservedIdentifier(id) ? "kw_" + id : id; };
  std::string id = stem;
  if (taken_.count(id)) id = free(fmt::format("{}_{}", stem, index));
  // A name that already ended in "_<index>" can still collide; count upwards.
  for (int k = 2; taken_.count(id); ++k) id = free(fmt::format("{}_{}_{}", stem, index, k));
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

std::string cStringLiteral(const std::string& text) {
  std::string out = "\"";
  for (std::size_t k = 0; k < text.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(text[k]);
    // A '*' next to a '/' is escaped too: the file then holds no "/*" or "*/"
    // anywhere, as for names in comments (tests/fuzz/fuzz_emit.cpp checks the text).
    const bool nextToSlash = c == '*' && ((k > 0 && text[k - 1] == '/') || (k + 1 < text.size() && text[k + 1] == '/'));
    if (c == '"' || c == '\\' || c == '?') out += std::string("\\") + char(c);
    else if (c >= 0x20 && c < 0x7f && !nextToSlash) out += char(c);
    else out += fmt::format("\\{:03o}", c);
  }
  return out + "\"";
}

}  // namespace proxgen::emit

// Names from a URDF or a layout never reach generated code raw. They become
// C++ identifiers through sanitizeIdentifier (and are made unique by
// IdentifierSet), and text in comments goes through escapeComment.
#pragma once

#include <cstddef>
#include <set>
#include <string>

namespace proxgen::emit {

/// Longest identifier stem produced (before a uniqueness suffix).
inline constexpr std::size_t kMaxIdentifierLength = 48;
/// Longest comment text produced from one name (longer text is cut and marked).
inline constexpr std::size_t kMaxCommentLength = 120;

/// A safe C++ identifier derived from `name`: ASCII letters, digits and single
/// underscores only; never empty, never starting with a digit or an underscore,
/// never ending with an underscore, never containing "__", never reserved
/// (isReservedIdentifier: a reserved name gets the prefix "kw_"); at most
/// kMaxIdentifierLength characters, the prefix included.
std::string sanitizeIdentifier(const std::string& name);

/// True for names the generated files must not declare as a namespace or use
/// as a name: C++ keywords and alternative tokens, every global name and macro
/// of the C and C++ standard libraries and POSIX (reserved_names.inc), the
/// families those standards reserve (`*_t`, `E[0-9A-Z]*`, `M_*`, `INT*_MAX`, ...),
/// common macros of other headers, and the runtime's and files' own names
/// (`proxgen_rt`, `Scalar`, `Settings`, `Workspace`).
bool isReservedIdentifier(const std::string& id);

/// Hands out unique identifiers: a sanitised name that is already taken gets
/// the suffix "_<index>" (the body or constraint index the caller passes).
class IdentifierSet {
 public:
  std::string make(const std::string& name, int index);
  bool contains(const std::string& id) const { return taken_.count(id) > 0; }

 private:
  std::set<std::string> taken_;
};

/// Text safe inside a // comment or a /* */ comment: printable ASCII only
/// (other bytes, control characters and backslashes as \xNN), no "*/", no "??"
/// (trigraphs), cut at kMaxCommentLength characters with the byte count noted.
std::string escapeComment(const std::string& text);

/// `text` as a C and C++ string literal, quotes included, that holds exactly
/// its bytes: printable ASCII as is, except `"`, `\` and `?` (no trigraph)
/// escaped by a backslash; every other byte, and a `*` next to a `/` (no
/// comment token), as a three-digit octal escape (which, unlike \x, cannot
/// run into the next character).
std::string cStringLiteral(const std::string& text);

}  // namespace proxgen::emit

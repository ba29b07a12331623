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
/// never ending with an underscore, never containing "__", never a keyword,
/// an alternative token or a macro of the standard headers; at most
/// kMaxIdentifierLength characters.
std::string sanitizeIdentifier(const std::string& name);

/// True for C++ keywords, alternative tokens and reserved names the generated
/// files must not declare (standard macros, `std`, the runtime's namespace).
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

}  // namespace proxgen::emit

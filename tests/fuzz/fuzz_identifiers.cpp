// Names -> identifiers and comment text (generator/emit/identifiers.hpp): the
// properties that keep a hostile URDF name from injecting code, checked on
// arbitrary bytes.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string>

#include "emit/identifiers.hpp"
#include "fuzz_common.hpp"

namespace {

using proxgen::fuzz::broken;

void checkIdentifier(const std::string& name, const std::string& id, std::size_t maxLength) {
  if (id.empty() || id.size() > maxLength) broken("identifier length", name + " -> " + id);
  if (!std::isalpha(static_cast<unsigned char>(id[0]))) broken("identifier must start with a letter", id);
  for (unsigned char c : id)
    if (!(c < 0x80 && (std::isalnum(c) || c == '_'))) broken("identifier character", id);
  if (id.find("__") != std::string::npos || id.back() == '_') broken("reserved underscore pattern", id);
  if (proxgen::emit::isReservedIdentifier(id)) broken("reserved identifier", id);
}

void checkComment(const std::string& text) {
  const std::string c = proxgen::emit::escapeComment(text);
  // At most kMaxCommentLength input bytes are shown, each as itself or as a
  // 4-character \xNN escape, then a cut-off note of under 40 characters.
  if (c.size() > 4 * proxgen::emit::kMaxCommentLength + 40) broken("comment length", c);
  for (unsigned char ch : c)
    if (ch < 0x20 || ch >= 0x7f) broken("comment byte not printable ASCII", c);
  if (c.find("*/") != std::string::npos || c.find("/*") != std::string::npos) broken("comment delimiter", c);
  if (c.find("??") != std::string::npos) broken("trigraph in comment", c);
  if (!c.empty() && c.back() == '\\') broken("line continuation in comment", c);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string name(reinterpret_cast<const char*>(data), size);
  const std::string id = proxgen::emit::sanitizeIdentifier(name);
  checkIdentifier(name, id, proxgen::emit::kMaxIdentifierLength);
  // Two different names must still give two different identifiers.
  proxgen::emit::IdentifierSet set;
  const std::string a = set.make(name, 1), b = set.make(name, 2);
  if (a == b) broken("IdentifierSet handed out a name twice", a);
  checkIdentifier(name, b, proxgen::emit::kMaxIdentifierLength + 12);
  checkComment(name);
  return 0;
}

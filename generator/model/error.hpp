// The one exception type of the host library: a message that names the file,
// the element and what is wrong. The CLI prints it on one line and exits 1.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace proxgen {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// "FILE: ELEMENT: WHAT" (ELEMENT may be empty).
std::string describe(const std::string& file, const std::string& element, const std::string& what);

[[noreturn]] void fail(const std::string& file, const std::string& element, const std::string& what);

/// A name as it appears in an error message: quoted, control characters escaped,
/// cut at 80 characters so a hostile 10 kB name cannot flood a terminal.
std::string quoted(const std::string& name);

/// A third-party library's message (urdfdom, yaml-cpp, nlohmann-json) made fit
/// for ours: control characters escaped, cut after `maxShown` characters.
std::string oneLine(const std::string& text, std::size_t maxShown = 200);

/// Edit distance between two names (insertions, deletions, substitutions and
/// swaps of two neighbours each count 1), over their first 100 bytes only: a
/// suggestion needs no more, and a 10 kB hostile name stays cheap.
std::size_t editDistance(const std::string& a, const std::string& b);

/// The `count` candidates closest to `name` by editDistance, nearest first
/// (ties in the candidates' order, so messages are deterministic). For "did
/// you mean" lists: the names a user meant are usually a typo away.
std::vector<std::string> closestNames(const std::string& name, const std::vector<std::string>& candidates,
                                      std::size_t count);

/// "'a', 'b' or 'c'": names quoted and joined for a message.
std::string quotedList(const std::vector<std::string>& names, const char* lastJoin = " or ");

}  // namespace proxgen

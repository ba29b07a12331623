// The one exception type of the host library: a message that names the file,
// the element and what is wrong. The CLI prints it on one line and exits 1.
#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace proxgen

// Warnings: input that is accepted but almost certainly not what the author
// meant (a <mimic> naming no joint, a constraint on a link fixed to the world,
// a negligible link whose inertia is not positive semi-definite). Shaped like
// the errors, "FILE: ELEMENT: WHAT" (describe() in error.hpp), one line each,
// and printed through this one function as `proxgen: warning: ...` on stderr.
// They are held until the command has succeeded (flushWarnings, called by the
// CLI's main): bad input still prints exactly one line, its error.
#pragma once

#include <functional>
#include <string>

namespace proxgen {

/// Reports one warning: the line goes to the current sink (by default, the
/// lines held for flushWarnings) and is returned, so the loader can also
/// record it (Model::warnings).
std::string warn(const std::string& file, const std::string& element, const std::string& what);

/// The same for a line already shaped like an error ("FILE: ELEMENT: WHAT").
std::string warnLine(const std::string& line);

/// Prints the held warnings on stderr, `proxgen: warning: LINE` each, escaped
/// like the errors (oneLine), and forgets them.
void flushWarnings();

/// Where warnings go; a test captures them with its own sink. Returns the old one.
/// An empty function restores the default (held for flushWarnings).
using WarningSink = std::function<void(const std::string& line)>;
WarningSink setWarningSink(WarningSink sink);

}  // namespace proxgen

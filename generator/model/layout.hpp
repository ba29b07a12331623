// Constraint layout (YAML) -> Layout, and the loading of a whole System.
#pragma once

#include <string>

#include "model/model.hpp"

namespace proxgen {

/// Reads a layout file. Unknown keys are errors (a typo must not silently drop a
/// constraint). Throws proxgen::Error ("FILE:LINE: element: what is wrong").
Layout loadLayout(const std::string& path);
Layout parseLayout(const std::string& yaml, const std::string& path);

/// URDF + layout -> System: the one entry point every command uses.
System loadSystem(const std::string& urdfPath, const std::string& layoutPath);

/// A System with no constraints (fixed or floating base), for `check` without a layout.
System loadSystemWithoutLayout(const std::string& urdfPath, bool floatingBase);

}  // namespace proxgen

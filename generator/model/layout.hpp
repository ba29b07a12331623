// Constraint layout (YAML) -> Layout, and the loading of a whole System.
#pragma once

#include <string>

#include "model/model.hpp"

namespace proxgen {

/// Most constraint rows a layout may declare (6 per weld, 3 per point contact).
/// The generic solvers' memory grows with their square (proxPV keeps an m x m
/// block per support body: at most 256^2 * kMaxTreeDepth doubles = 0.27 GB);
/// real layouts have under 50 (docs/guarantees.md).
inline constexpr int kMaxConstraintRows = 256;

/// Most multiplier updates K a layout may ask for (`iterations`), as on the
/// command line (`--iterations`): beyond it a typo, not a request, and K mu kp e
/// (the multipliers of an inconsistent row grow with K) would leave the range
/// kMaxInputMagnitude keeps.
inline constexpr int kMaxIterations = 1000000;

/// Reads a layout file. Unknown keys are errors (a typo must not silently drop a
/// constraint). Throws proxgen::Error ("FILE:LINE: element: what is wrong").
Layout loadLayout(const std::string& path);
Layout parseLayout(const std::string& yaml, const std::string& path);

/// URDF + layout -> System: the one entry point every command uses.
System loadSystem(const std::string& urdfPath, const std::string& layoutPath);

/// A System with no constraints (fixed or floating base), for `check` without a layout.
System loadSystemWithoutLayout(const std::string& urdfPath, bool floatingBase);

}  // namespace proxgen

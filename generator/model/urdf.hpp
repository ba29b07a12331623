// URDF -> Model (through urdfdom).
#pragma once

#include <string>

#include "model/model.hpp"

namespace proxgen {

/// Largest URDF file read (bytes). Larger files are refused before parsing, so a
/// huge input fails fast with a clear message instead of exhausting memory.
inline constexpr std::size_t kMaxUrdfBytes = 64u << 20;

/// Reads a URDF file into a Model. With `floatingBase` the root link becomes a
/// free-flyer body (joint `root_joint`); otherwise it is welded to the world.
/// Throws proxgen::Error ("FILE:LINE: joint 'x': what is wrong") on bad input.
Model loadUrdf(const std::string& path, bool floatingBase);

/// The same from a string already in memory; `path` is only used in messages.
Model parseUrdf(const std::string& xml, const std::string& path, bool floatingBase);

}  // namespace proxgen

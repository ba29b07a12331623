// Plan -> text: the two files of a generated solver (templates/solver.*.tpl
// filled with fmt), printed by the passes (passes.hpp, one file per
// recursion; docs/emitter.md). Every body gets its own block, headed by a
// comment naming its link and joint; the arithmetic is printed through the
// expression printer (expr.hpp), so the constants of the tree (transforms,
// inertias, axes, constraint placements) are literals with their exact zeros
// and ones folded away.
#pragma once

#include <string>

#include "emit/plan.hpp"

namespace proxgen::emit {

/// What the banner of the files records about the inputs (names without
/// directories, so the files do not depend on where the inputs were).
struct SolverInputs {
  std::string urdfName, urdfSha256;
  std::string layoutName, layoutSha256;
  std::string command;  // how to regenerate (without the output folder)
  /// `--functions a,b|all` as given, overriding the layout's `functions:`
  /// ("": the layout's); recorded in the command.
  std::string functions;
};

struct SolverFiles {
  std::string headerName, header;  // NAME.hpp
  std::string sourceName, source;  // NAME.cpp
  // NAME.cpp as the passes printed it, without shared blocks
  // (emit/shared_blocks.hpp): what the batched files are cut from (their lanes
  // keep every block inline); the same text as `source` where nothing is shared.
  std::string unsharedSource;
  // The C interface (emit/c_api.hpp): NAME_c.h, NAME_c.cpp.
  std::string cHeaderName, cHeader, cSourceName, cSource;
};

/// Size statistics of an emitted solver (live statements, multiplications).
struct SolverStats {
  int statements = 0, temporaries = 0, multiplies = 0;
  int workspaceScalars = 0;
};

SolverFiles emitSolver(const System& sys, const Plan& plan, const SolverInputs& inputs, SolverStats* stats = nullptr);

}  // namespace proxgen::emit

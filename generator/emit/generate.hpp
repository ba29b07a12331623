// `proxgen generate` as a library call: URDF + layout -> plan -> the two files
// of a solver, written atomically (both or nothing) into the output folder.
#pragma once

#include <string>

#include "emit/emitter.hpp"

namespace proxgen::emit {

/// What `generate` accepts beyond the loaders' limits (docs/guarantees.md,
/// "Resource bounds"). The emitter hands its whole state (every body's
/// quantities, and the constraint columns each support body carries) to each
/// part function it starts, so its time grows with the square of the robot:
/// these keep it to about a minute of CPU, where the loaders' 4096 links
/// take almost four (217 s at a 4095-body tree).
inline constexpr int kMaxGenerateBodies = 1024;  // moving bodies (after fixed-joint merging)
/// Rows carried through the support: the sum over the support bodies of the
/// constraint rows in their subtrees (the columns of their KA).
inline constexpr int kMaxGenerateSupportRows = 4096;

struct GenerateOptions {
  std::string urdf, layout;  // input files
  /// Instead of urdf + layout: one case of a cases file (cases.yaml: a list of
  /// layouts with `name` and `model`), as the tests and benchmarks use them.
  std::string casesFile, caseName;
  std::string name;          // namespace and file stem; "" = the case name or the URDF's file stem
  ScalarType scalar = ScalarType::Double;
};

/// Loads the inputs and prints the solver in memory. Throws proxgen::Error
/// (the loaders' messages) on bad input.
SolverFiles generateFiles(const GenerateOptions& options, SolverStats* stats = nullptr);

/// Writes the files into `outDir` (created if missing): each to a temporary
/// file in that folder, then renamed, so a failure leaves nothing new behind.
/// Returns the paths written.
std::vector<std::string> writeFiles(const SolverFiles& files, const std::string& outDir);

/// "double" / "float" -> ScalarType; throws proxgen::Error otherwise.
ScalarType parseScalar(const std::string& s);

}  // namespace proxgen::emit

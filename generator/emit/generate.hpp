// `proxgen generate` as a library call: URDF + layout -> plan -> the two files
// of a solver, written atomically (both or nothing) into the output folder.
#pragma once

#include <string>

#include "emit/emitter.hpp"

namespace proxgen::emit {

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

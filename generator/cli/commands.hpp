// The `proxgen` subcommands. Each registers itself on the CLI11 app and runs
// through a callback; errors are proxgen::Error, printed by main on one line.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "emit/emitter.hpp"

namespace proxgen::cli {

void addCheck(CLI::App& app);     // check.cpp
void addEval(CLI::App& app);      // eval.cpp
void addGenerate(CLI::App& app);  // generate.cpp
void addVerify(CLI::App& app);    // verify.cpp

/// `eval --compute QUANTITY`: the dynamics library on the states, as JSON
/// (compute.cpp). mu <= 0 means the layout's; iterations (derivatives only)
/// < 0 means not given: the converged solve, 200.
void runCompute(const std::string& urdf, const std::string& layout, const std::string& state, const std::string& quantity,
                double mu, int iterations = -1);

/// The robot of `generate` and `verify`: a URDF and --layout, or --cases and
/// --case, never a mix (generate.cpp).
void checkRobotOptions(const char* command, const std::string& urdf, const std::string& layout,
                       const std::string& cases, const std::string& caseName);

/// The solver of `generate`'s options (generate.cpp): a URDF and a layout, or a
/// case; with --scalar float, the float-accuracy warning (if any) on stderr.
/// `loaded`, if given, receives the System the solver was generated from.
emit::SolverFiles generateSolverFiles(const std::string& urdf, const std::string& layout, const std::string& cases,
                                      const std::string& caseName, const std::string& name, emit::ScalarType scalar,
                                      System* loaded = nullptr, const std::string& functions = "");

/// The warning that a float constrainedABA loses accuracy with this layout
/// ("" if none; check.cpp). Printed when float is asked for: generate and
/// verify with --scalar float, check with --scalar float.
std::string floatAccuracyWarning(const System& sys);
void printWarning(const std::string& text);

}  // namespace proxgen::cli

// `proxgen generate` as a library call: URDF + layout -> System -> plan -> the
// two files of a solver, written atomically (both or nothing) into the output
// folder (emit/output.hpp). One pipeline: every way in (files here, a case of a
// cases file in cases/cases.hpp) loads a System and calls generateSystem.
#pragma once

#include <string>
#include <vector>

#include "emit/emitter.hpp"
#include "emit/output.hpp"

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
  std::string name;          // namespace and file stem; "" = the URDF's file stem
  ScalarType scalar = ScalarType::Double;
  std::string functions;     // --functions a,b|all ("" = the layout's functions:)
};

/// Loads the inputs and prints the solver in memory. Throws proxgen::Error
/// (the loaders' messages) on bad input.
/// `system`, if given, receives the loaded System (for the CLI's warnings).
SolverFiles generateFiles(const GenerateOptions& options, SolverStats* stats = nullptr, System* system = nullptr);

/// The pipeline after loading: the plan of `sys` under `name` (sanitised) and
/// the emitted files. `in` describes the inputs for the files' banner; its
/// `command` is the command's start ("proxgen generate arm.urdf --layout
/// layout.yaml"), completed here with --out, --name, --scalar and (if given)
/// --functions, which replaces sys.functions (an unknown name is an error).
SolverFiles generateSystem(const System& sys, const std::string& name, ScalarType scalar, SolverInputs in,
                           SolverStats* stats = nullptr);

/// The solver's files as outputs for writeFiles (emit/output.hpp): NAME.hpp,
/// NAME.cpp and its C interface, NAME_c.h and NAME_c.cpp (emit/c_api.hpp).
std::vector<OutputFile> solverOutputs(const SolverFiles& files);

/// "double" / "float" -> ScalarType; throws proxgen::Error otherwise.
ScalarType parseScalar(const std::string& s);

}  // namespace proxgen::emit

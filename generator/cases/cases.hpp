// The benchmark cases file (`cases.yaml`: a `cases:` list whose items are
// layouts plus `name` and `model`), a format of the tests and the benchmarks
// (and of `generate --cases`, `verify --cases`), kept out of the library's core
// (the proxgen_cases target): a case is loaded into a System and goes through
// the one pipeline of emit/generate.hpp.
#pragma once

#include <string>
#include <vector>

#include "emit/emitter.hpp"
#include "model/model.hpp"

namespace proxgen {

struct Case {
  std::string name;
  std::string urdfPath;  // resolved relative to the cases file
  Layout layout;
};

std::vector<Case> loadCases(const std::string& path);

/// The case called `name` of the cases file `path`; an Error naming the file
/// when there is none.
Case loadCase(const std::string& path, const std::string& name);

/// Loads the System of one case.
System loadCaseSystem(const Case& c);

/// `proxgen generate --cases FILE --case NAME`: the solver of one case
/// (emit::generateSystem); `name` "" = the case's name.
/// `functions`: --functions as given ("" = the case's layout's).
emit::SolverFiles generateCase(const std::string& casesFile, const std::string& caseName, const std::string& name,
                               emit::ScalarType scalar, emit::SolverStats* stats = nullptr, System* system = nullptr,
                               const std::string& functions = "");

/// `generate`'s two ways in (the CLI and the Python package): one case of a
/// cases file when `casesFile` is set, else a URDF and a layout. `system`, if
/// given, receives the System the solver was generated from.
emit::SolverFiles generateFromInputs(const std::string& urdf, const std::string& layout, const std::string& casesFile,
                                     const std::string& caseName, const std::string& name, emit::ScalarType scalar,
                                     System* system = nullptr, const std::string& functions = "");

}  // namespace proxgen

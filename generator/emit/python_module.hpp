// Plan -> NAME_python.cpp: the pybind11 module over a generated solver
// (templates/python_module.cpp.tpl, bound by python/include/proxgen/python_module.hpp).
// `proxgen generate --python` writes it beside NAME.hpp and NAME.cpp.
#pragma once

#include <string>

#include "emit/generate.hpp"
#include "emit/plan.hpp"
#include "model/functions.hpp"

namespace proxgen::emit {

struct PythonModuleFile {
  std::string name, text;  // NAME_python.cpp
};

/// The module source for a plan, binding the solvers and library functions in
/// `functions` (the set the solver was generated with); joint and constraint
/// names become C++ string literals with every byte outside printable ASCII
/// (and quotes, backslashes, '?') as an octal escape, so no name from a URDF
/// reaches the code raw.
PythonModuleFile emitPythonModule(const Plan& plan, const FunctionSet& functions);

/// NAME_python.cpp for the solver `files` generated from `sys` (same plan name
/// and scalar), as an output for writeFiles: it is written atomically with the
/// solver's own files.
OutputFile pythonModuleOutput(const System& sys, const SolverFiles& files, ScalarType scalar);

/// A C++ string literal (with its quotes) holding exactly the bytes of `s`.
std::string cppStringLiteral(const std::string& s);

}  // namespace proxgen::emit

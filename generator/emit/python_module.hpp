// Plan -> NAME_python.cpp: the pybind11 module over a generated solver
// (templates/python_module.cpp.tpl, bound by python/include/proxgen/python_module.hpp).
// `proxgen generate --python` writes it beside NAME.hpp and NAME.cpp.
#pragma once

#include <string>

#include "emit/generate.hpp"
#include "emit/plan.hpp"

namespace proxgen::emit {

struct PythonModuleFile {
  std::string name, text;  // NAME_python.cpp
};

/// The module source for a plan; joint and constraint names become C++ string
/// literals with every byte outside printable ASCII (and quotes, backslashes,
/// '?') as an octal escape, so no name from a URDF reaches the code raw.
PythonModuleFile emitPythonModule(const Plan& plan);

/// The same for what `generateFiles(options)` generates (loads the inputs again).
PythonModuleFile generatePythonModule(const GenerateOptions& options);

/// Writes one file into `outDir` (which writeFiles created) through a
/// temporary file and a rename. Returns its path.
std::string writePythonModule(const PythonModuleFile& file, const std::string& outDir);

/// A C++ string literal (with its quotes) holding exactly the bytes of `s`.
std::string cppStringLiteral(const std::string& s);

}  // namespace proxgen::emit

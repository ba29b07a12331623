// Plan -> NAME_c.h and NAME_c.cpp: the C interface of a generated solver
// (templates/solver_c.*.tpl; docs/design.md, "The C interface"). Every
// function the solver holds gets an extern "C" twin over plain arrays and a
// caller-provided work buffer; `generate` writes both files with the solver's
// (emit/generate.cpp, solverOutputs), proxgen_add_solver compiles the source
// into the solver's library.
#pragma once

#include <string>

#include "emit/plan.hpp"
#include "model/functions.hpp"

namespace proxgen::emit {

struct CInterfaceFiles {
  std::string headerName, header;  // NAME_c.h
  std::string sourceName, source;  // NAME_c.cpp
};

/// The prefix of every C name: the namespace name (plan.name), unless one of
/// the names it makes (NAME_NQ, NAME_work_size, ..., NAME_CONSTRAINT_<c>) is
/// reserved by the C or C++ library (isReservedIdentifier: "M" makes M_NQ, a
/// <math.h> family): then "kw_" + the name, as the sanitiser does.
std::string cPrefix(const Plan& plan);

/// The two files; `banner` is the solver's (templates/banner.tpl),
/// `workspaceBytes` sizeof(Workspace) (checked by the source's static_assert).
CInterfaceFiles emitCInterface(const Plan& plan, const FunctionSet& functions, const std::string& banner,
                               int workspaceBytes);

}  // namespace proxgen::emit

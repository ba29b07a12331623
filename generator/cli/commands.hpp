// The `proxgen` subcommands. Each registers itself on the CLI11 app and runs
// through a callback; errors are proxgen::Error, printed by main on one line.
#pragma once

#include <CLI/CLI.hpp>

namespace proxgen::cli {

void addCheck(CLI::App& app);     // check.cpp
void addEval(CLI::App& app);      // eval.cpp
void addGenerate(CLI::App& app);  // generate.cpp
void addVerify(CLI::App& app);    // verify.cpp

}  // namespace proxgen::cli

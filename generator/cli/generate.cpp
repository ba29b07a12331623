// proxgen generate robot.urdf --layout layout.yaml --out DIR [--name NAME] [--scalar double|float] [--python]
//                  [--functions a,b,...|all] [--batch W]
//   or, for one case of a cases file (tests, benchmarks):
// proxgen generate --cases cases.yaml --case NAME --out DIR [--name NAME] [--scalar double|float]
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include "cli/commands.hpp"
#include "cases/cases.hpp"
#include "emit/batch.hpp"
#include "emit/generate.hpp"
#include "emit/python_module.hpp"
#include "model/error.hpp"

namespace proxgen::cli {

void checkRobotOptions(const char* command, const std::string& urdf, const std::string& layout,
                       const std::string& cases, const std::string& caseName) {
  const bool byCase = !cases.empty() || !caseName.empty();
  if (byCase && (cases.empty() || caseName.empty() || !urdf.empty() || !layout.empty()))
    throw Error(fmt::format("{}: --cases and --case go together, without a URDF or --layout", command));
  if (!byCase && (urdf.empty() || layout.empty()))
    throw Error(fmt::format("{}: needs a URDF and --layout (or --cases and --case)", command));
}

emit::SolverFiles generateSolverFiles(const std::string& urdf, const std::string& layout, const std::string& cases,
                                      const std::string& caseName, const std::string& name, emit::ScalarType scalar,
                                      System* loaded, const std::string& functions) {
  System sys;
  const emit::SolverFiles files = generateFromInputs(urdf, layout, cases, caseName, name, scalar, &sys, functions);
  if (scalar == emit::ScalarType::Float) printWarning(floatAccuracyWarning(sys));
  if (loaded) *loaded = std::move(sys);
  return files;
}

void addGenerate(CLI::App& app) {
  struct Options {
    std::string urdf, layout, cases, caseName, out, name, scalar = "double", functions;
    bool python = false;
    std::string batchText;  // --batch W as given (parseBatchWidth)
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("generate", "write a flat C++ solver (NAME.hpp, NAME.cpp) and its C interface (NAME_c.h, NAME_c.cpp) for one robot and layout");
  cmd->add_option("urdf", opt->urdf, "robot URDF");
  cmd->add_option("--layout", opt->layout, "constraint layout (YAML)");
  cmd->add_option("--cases", opt->cases, "a cases file (cases.yaml), instead of URDF and layout");
  cmd->add_option("--case", opt->caseName, "the case of --cases to generate");
  cmd->add_option("--out", opt->out, "output folder (created if missing)")->required();
  cmd->add_option("--name", opt->name, "namespace and file name (sanitised; default: the case or the URDF's file name)");
  cmd->add_option("--scalar", opt->scalar, "double (default) or float")->check(CLI::IsMember({"double", "float"}));
  cmd->add_option("--functions", opt->functions,
                  "the functions the solver holds, a,b,... or all (default: the layout's functions:, else "
                  "constrained_aba,prox_pv; valid: " + functionNameList() + ")");
  CLI::Option* batchOption = cmd->add_option("--batch", opt->batchText,
                  "also write NAME_batch.hpp and NAME_batch.cpp, the solvers (and the library functions held) over W "
                  "states per call in the lanes of a vector register (2, 4, 8 or 16; docs/batch.md)")
      ->type_name("W");
  cmd->add_flag("--python", opt->python, "also write NAME_python.cpp, a pybind11 module over the solver (docs/python.md)");
  cmd->callback([opt, batchOption] {
    checkRobotOptions("generate", opt->urdf, opt->layout, opt->cases, opt->caseName);
    // (a bad width is refused before any work)
    const int batchWidth = emit::parseBatchWidth(opt->batchText, batchOption->count() > 0);
    System sys;
    const emit::SolverFiles files = generateSolverFiles(opt->urdf, opt->layout, opt->cases, opt->caseName, opt->name,
                                                        emit::parseScalar(opt->scalar), &sys, opt->functions);
    std::vector<emit::OutputFile> outputs = emit::solverOutputs(files);
    // The module source goes through the same atomic write as the solver's files.
    if (opt->python) outputs.push_back(emit::pythonModuleOutput(sys, files, emit::parseScalar(opt->scalar)));
    if (batchWidth != 0) {
      const emit::BatchFiles batch = emit::batchFiles(files, batchWidth);
      outputs.push_back({batch.headerName, batch.header});
      outputs.push_back({batch.sourceName, batch.source});
    }
    for (const std::string& path : emit::writeFiles(outputs, opt->out))
      std::printf("wrote %s\n", oneLine(path, 1000).c_str());
  });
}

}  // namespace proxgen::cli

// proxgen generate robot.urdf --layout layout.yaml --out DIR [--name NAME] [--scalar double|float] [--python]
//   or, for one case of a cases file (tests, benchmarks):
// proxgen generate --cases cases.yaml --case NAME --out DIR [--name NAME] [--scalar double|float]
#include <fmt/format.h>

#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
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

void addGenerate(CLI::App& app) {
  struct Options {
    std::string urdf, layout, cases, caseName, out, name, scalar = "double";
    bool python = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("generate", "write a flat C++ solver (NAME.hpp, NAME.cpp) for one robot and layout");
  cmd->add_option("urdf", opt->urdf, "robot URDF");
  cmd->add_option("--layout", opt->layout, "constraint layout (YAML)");
  cmd->add_option("--cases", opt->cases, "a cases file (cases.yaml), instead of URDF and layout");
  cmd->add_option("--case", opt->caseName, "the case of --cases to generate");
  cmd->add_option("--out", opt->out, "output folder (created if missing)")->required();
  cmd->add_option("--name", opt->name, "namespace and file name (sanitised; default: the case or the URDF's file name)");
  cmd->add_option("--scalar", opt->scalar, "double (default) or float")->check(CLI::IsMember({"double", "float"}));
  cmd->add_flag("--python", opt->python, "also write NAME_python.cpp, a pybind11 module over the solver (docs/python.md)");
  cmd->callback([opt] {
    checkRobotOptions("generate", opt->urdf, opt->layout, opt->cases, opt->caseName);
    emit::GenerateOptions g;
    g.urdf = opt->urdf;
    g.layout = opt->layout;
    g.casesFile = opt->cases;
    g.caseName = opt->caseName;
    g.name = opt->name;
    g.scalar = emit::parseScalar(opt->scalar);
    const emit::SolverFiles files = emit::generateFiles(g);
    const emit::PythonModuleFile module = opt->python ? emit::generatePythonModule(g) : emit::PythonModuleFile{};
    for (const std::string& path : emit::writeFiles(files, opt->out)) std::printf("wrote %s\n", path.c_str());
    // Not yet atomic with the two files above (writeFiles takes a list soon).
    if (opt->python) std::printf("wrote %s\n", emit::writePythonModule(module, opt->out).c_str());
  });
}

}  // namespace proxgen::cli

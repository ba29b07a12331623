#include "emit/generate.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "emit/hash.hpp"
#include "emit/plan.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"

namespace proxgen::emit {

namespace fs = std::filesystem;

ScalarType parseScalar(const std::string& s) {
  if (s == "double") return ScalarType::Double;
  if (s == "float") return ScalarType::Float;
  throw Error(fmt::format("--scalar: {} is not double or float", quoted(s)));
}

namespace {

const char* scalarName(ScalarType t) { return t == ScalarType::Float ? "float" : "double"; }

// generate's own size bounds (generate.hpp), before any printing.
void checkSize(const Plan& plan, const std::string& urdf, const std::string& layout) {
  const int bodies = int(plan.bodies.size()) - 1;
  if (bodies > kMaxGenerateBodies)
    fail(urdf, "robot",
         fmt::format("{} moving bodies: generate handles at most {} (its time grows with the square of the size; "
                     "check and eval read up to 4096 links)",
                     bodies, kMaxGenerateBodies));
  long rows = 0;
  for (int i : plan.support) rows += plan.bodies[std::size_t(i)].m();
  if (rows > kMaxGenerateSupportRows)
    fail(layout, "constraints",
         fmt::format("{} rows through {} support bodies ({} row-body pairs): generate handles at most {} "
                     "(fewer rows, or rows nearer the root)",
                     plan.nc, plan.support.size(), rows, kMaxGenerateSupportRows));
}

}  // namespace

SolverFiles generateSystem(const System& sys, const std::string& name, ScalarType scalar, SolverInputs in,
                           SolverStats* stats) {
  if (!in.functions.empty()) {
    System selected = sys;
    selected.functions = parseFunctionList(in.functions, "command line", "--functions");
    std::string list = in.functions;
    in.functions.clear();
    in.command += " --functions " + list;
    return generateSystem(selected, name, scalar, in, stats);
  }
  const Plan plan = makePlan(sys, name, scalar);
  checkSize(plan, sys.model.sourcePath, sys.layoutPath);
  in.command = fmt::format("{} --out DIR --name {} --scalar {}", in.command, plan.name, scalarName(scalar));
  return emitSolver(sys, plan, in, stats);
}

SolverFiles generateFiles(const GenerateOptions& options, SolverStats* stats, System* system) {
  System sys = loadSystem(options.urdf, options.layout);
  if (!options.functions.empty()) sys.functions = parseFunctionList(options.functions, "command line", "--functions");
  if (system) *system = sys;
  const std::string name = options.name.empty() ? fs::path(options.urdf).stem().string() : options.name;
  SolverInputs in;
  in.urdfName = fs::path(options.urdf).filename().string();
  in.layoutName = fs::path(options.layout).filename().string();
  in.urdfSha256 = sha256File(options.urdf, "URDF");
  in.layoutSha256 = sha256File(options.layout, "layout");
  in.command = fmt::format("proxgen generate {} --layout {}", in.urdfName, in.layoutName);
  in.functions = options.functions;
  return generateSystem(sys, name, options.scalar, in, stats);
}

std::vector<OutputFile> solverOutputs(const SolverFiles& files) {
  return {{files.headerName, files.header},
          {files.sourceName, files.source},
          {files.cHeaderName, files.cHeader},
          {files.cSourceName, files.cSource}};
}

}  // namespace proxgen::emit

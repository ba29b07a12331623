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

}  // namespace

SolverFiles generateSystem(const System& sys, const std::string& name, ScalarType scalar, SolverInputs in,
                           SolverStats* stats) {
  const Plan plan = makePlan(sys, name, scalar);
  in.command = fmt::format("{} --out DIR --name {} --scalar {}", in.command, plan.name, scalarName(scalar));
  return emitSolver(sys, plan, in, stats);
}

SolverFiles generateFiles(const GenerateOptions& options, SolverStats* stats, System* system) {
  const System sys = loadSystem(options.urdf, options.layout);
  if (system) *system = sys;
  const std::string name = options.name.empty() ? fs::path(options.urdf).stem().string() : options.name;
  SolverInputs in;
  in.urdfName = fs::path(options.urdf).filename().string();
  in.layoutName = fs::path(options.layout).filename().string();
  in.urdfSha256 = sha256File(options.urdf);
  in.layoutSha256 = sha256File(options.layout);
  in.command = fmt::format("proxgen generate {} --layout {}", in.urdfName, in.layoutName);
  return generateSystem(sys, name, options.scalar, in, stats);
}

std::vector<OutputFile> solverOutputs(const SolverFiles& files) {
  return {{files.headerName, files.header}, {files.sourceName, files.source}};
}

}  // namespace proxgen::emit

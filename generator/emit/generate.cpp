#include "emit/generate.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "emit/hash.hpp"
#include "emit/plan.hpp"
#include "model/cases.hpp"
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

SolverFiles generateCase(const GenerateOptions& options, SolverStats* stats) {
  const Case c = loadCase(options.casesFile, options.caseName);
  const System sys = loadCaseSystem(c);
  const Plan plan = makePlan(sys, options.name.empty() ? c.name : options.name, options.scalar);
  checkSize(plan, c.urdfPath, options.casesFile);
  SolverInputs in;
  in.urdfName = fs::path(c.urdfPath).filename().string();
  in.layoutName = fmt::format("{} (case {})", fs::path(options.casesFile).filename().string(), c.name);
  in.urdfSha256 = sha256File(c.urdfPath);
  in.layoutSha256 = sha256File(options.casesFile);
  in.command = fmt::format("proxgen generate --cases {} --case {} --out DIR --name {} --scalar {}",
                           fs::path(options.casesFile).filename().string(), c.name, plan.name,
                           scalarName(options.scalar));
  return emitSolver(sys, plan, in, stats);
}

}  // namespace

SolverFiles generateFiles(const GenerateOptions& options, SolverStats* stats) {
  if (!options.casesFile.empty()) return generateCase(options, stats);
  const System sys = loadSystem(options.urdf, options.layout);
  const std::string name = options.name.empty() ? fs::path(options.urdf).stem().string() : options.name;
  const Plan plan = makePlan(sys, name, options.scalar);
  checkSize(plan, options.urdf, options.layout);
  SolverInputs in;
  in.urdfName = fs::path(options.urdf).filename().string();
  in.layoutName = fs::path(options.layout).filename().string();
  in.urdfSha256 = sha256File(options.urdf);
  in.layoutSha256 = sha256File(options.layout);
  in.command = fmt::format("proxgen generate {} --layout {} --out DIR --name {} --scalar {}", in.urdfName,
                           in.layoutName, plan.name, scalarName(options.scalar));
  return emitSolver(sys, plan, in, stats);
}

namespace {

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), std::streamsize(text.size()));
  out.close();
  if (!out) throw Error(fmt::format("{}: cannot be written", path.string()));
}

}  // namespace

std::vector<std::string> writeFiles(const SolverFiles& files, const std::string& outDir) {
  const fs::path dir(outDir);
  std::error_code ec;
  const bool existed = fs::is_directory(dir, ec);
  if (!existed && fs::exists(dir, ec)) throw Error(fmt::format("{}: exists and is not a folder", outDir));
  if (!existed && !fs::create_directories(dir, ec) && ec)
    throw Error(fmt::format("{}: cannot create the folder ({})", outDir, ec.message()));
  const std::vector<std::pair<fs::path, const std::string*>> out = {{dir / files.headerName, &files.header},
                                                                     {dir / files.sourceName, &files.source}};
  std::vector<fs::path> temps;
  try {
    for (const auto& [path, text] : out) {
      temps.push_back(dir / ("." + path.filename().string() + ".proxgen-tmp"));
      writeText(temps.back(), *text);
    }
    for (std::size_t k = 0; k < out.size(); ++k) {
      fs::rename(temps[k], out[k].first, ec);
      if (ec) throw Error(fmt::format("{}: cannot be written ({})", out[k].first.string(), ec.message()));
    }
  } catch (...) {
    for (const fs::path& t : temps) fs::remove(t, ec);
    if (!existed) fs::remove(dir, ec);  // only removes it if empty
    throw;
  }
  return {out[0].first.string(), out[1].first.string()};
}

}  // namespace proxgen::emit

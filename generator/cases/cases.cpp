#include "cases/cases.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "emit/generate.hpp"
#include "emit/hash.hpp"
#include "model/error.hpp"
#include "model/input.hpp"
#include "model/layout.hpp"
#include "model/urdf.hpp"

namespace proxgen {

Case loadCase(const std::string& path, const std::string& name) {
  for (Case& c : loadCases(path))
    if (c.name == name) return std::move(c);
  fail(path, "cases", fmt::format("no case named {}", quoted(name)));
}

std::vector<Case> loadCases(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(readInputFile(path, 4u << 20, "cases"));  // a regular file only (a FIFO would hang)
  } catch (const YAML::Exception& e) {  // readInputFile has refused an unreadable file already
    fail(fmt::format("{}:{}", path, e.mark.line + 1), "", fmt::format("malformed YAML: {}", e.msg));
  }
  if (!root.IsMap() || !root["cases"] || !root["cases"].IsSequence()) fail(path, "cases", "expected a list `cases:`");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::vector<Case> out;
  for (std::size_t k = 0; k < root["cases"].size(); ++k) {
    YAML::Node item = YAML::Clone(root["cases"][k]);
    const std::string element = fmt::format("cases[{}]", k);
    if (!item.IsMap() || !item["name"] || !item["model"]) fail(path, element, "needs `name` and `model`");
    // Both are text: a list or a map there is an error, not a failed conversion.
    for (const char* key : {"name", "model"})
      if (!item[key].IsScalar())
        fail(fmt::format("{}:{}", path, item[key].Mark().line + 1), fmt::format("{}.{}", element, key),
             "expected a string, got a list or a map");
    Case c;
    c.name = item["name"].Scalar();
    c.urdfPath = (dir / item["model"].Scalar()).string();
    item.remove("name");
    item.remove("model");
    YAML::Emitter e;
    try {
      e << item;
    } catch (const YAML::Exception& x) {
      fail(path, element, fmt::format("cannot be read as a layout: {}", oneLine(x.msg)));
    }
    c.layout = parseLayout(e.c_str(), fmt::format("{} (case {})", path, c.name));
    out.push_back(std::move(c));
  }
  return out;
}

System loadCaseSystem(const Case& c) { return bindLayout(loadUrdf(c.urdfPath, c.layout.base()), c.layout); }

emit::SolverFiles generateCase(const std::string& casesFile, const std::string& caseName, const std::string& name,
                               emit::ScalarType scalar, emit::SolverStats* stats, System* system,
                               const std::string& functions) {
  namespace fs = std::filesystem;
  const Case c = loadCase(casesFile, caseName);
  System sys = loadCaseSystem(c);
  if (!functions.empty()) sys.functions = parseFunctionList(functions, "command line", "--functions");
  if (system) *system = sys;
  emit::SolverInputs in;
  const std::string file = fs::path(casesFile).filename().string();
  in.urdfName = fs::path(c.urdfPath).filename().string();
  in.layoutName = fmt::format("{} (case {})", file, c.name);
  in.urdfSha256 = emit::sha256File(c.urdfPath, "URDF");
  in.layoutSha256 = emit::sha256File(casesFile, "cases");
  in.command = fmt::format("proxgen generate --cases {} --case {}", file, c.name);
  in.functions = functions;
  return emit::generateSystem(sys, name.empty() ? c.name : name, scalar, in, stats);
}

emit::SolverFiles generateFromInputs(const std::string& urdf, const std::string& layout, const std::string& casesFile,
                                     const std::string& caseName, const std::string& name, emit::ScalarType scalar,
                                     System* system, const std::string& functions) {
  if (!casesFile.empty()) return generateCase(casesFile, caseName, name, scalar, nullptr, system, functions);
  emit::GenerateOptions g;
  g.urdf = urdf;
  g.layout = layout;
  g.name = name;
  g.scalar = scalar;
  g.functions = functions;
  return emit::generateFiles(g, nullptr, system);
}

}  // namespace proxgen

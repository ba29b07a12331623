#include "model/cases.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

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
  } catch (const YAML::BadFile&) {
    fail(path, "", "cannot open file");
  } catch (const YAML::Exception& e) {
    fail(fmt::format("{}:{}", path, e.mark.line + 1), "", fmt::format("malformed YAML: {}", e.msg));
  }
  if (!root.IsMap() || !root["cases"] || !root["cases"].IsSequence()) fail(path, "cases", "expected a list `cases:`");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::vector<Case> out;
  for (std::size_t k = 0; k < root["cases"].size(); ++k) {
    YAML::Node item = YAML::Clone(root["cases"][k]);
    const std::string element = fmt::format("cases[{}]", k);
    if (!item.IsMap() || !item["name"] || !item["model"]) fail(path, element, "needs `name` and `model`");
    Case c;
    c.name = item["name"].as<std::string>();
    c.urdfPath = (dir / item["model"].as<std::string>()).string();
    item.remove("name");
    item.remove("model");
    YAML::Emitter e;
    e << item;
    c.layout = parseLayout(e.c_str(), fmt::format("{} (case {})", path, c.name));
    out.push_back(std::move(c));
  }
  return out;
}

System loadCaseSystem(const Case& c) { return bindLayout(loadUrdf(c.urdfPath, c.layout.floatingBase), c.layout); }

}  // namespace proxgen

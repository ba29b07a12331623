// proxgen_bench_check_layouts CASES_YAML LAYOUT_DIR: the layout files the build
// generates the benchmark solvers from (bench/layouts/<case>.yaml, each naming
// its URDF in a `# model: FILE` comment) must say what cases.yaml says. Both are
// read by the library's own loaders and compared field by field; the numbers
// come from the same decimal text, so they must be equal exactly.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "cases/cases.hpp"
#include "model/layout.hpp"

namespace fs = std::filesystem;
using namespace proxgen;

namespace {

int failures = 0;

void expect(bool ok, const std::string& where, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "%s: %s\n", where.c_str(), what.c_str());
  ++failures;
}

bool same(const SE3& a, const SE3& b) { return a.R == b.R && a.p == b.p; }

// The URDF file a layout names in its "# model: FILE" comment ("" if none).
std::string modelComment(const fs::path& layout) {
  std::ifstream in(layout);
  const std::string key = "# model:";
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) != 0) continue;
    std::string v = line.substr(key.size());
    v.erase(0, v.find_first_not_of(" \t"));
    v.erase(v.find_last_not_of(" \t\r") + 1);
    return v;
  }
  return "";
}

void compareConstraint(const Constraint& a, const Constraint& b, const std::string& where) {
  expect(a.name == b.name, where, "name " + b.name + " != " + a.name);
  expect(a.link == b.link, where, "link " + b.link + " != " + a.link);
  expect(a.type == b.type, where, "type differs");
  expect(same(a.offset, b.offset), where, "offset differs");
  expect(a.kp == b.kp && a.kd == b.kd, where, "gains differ");
  expect(a.hasTarget == b.hasTarget && same(a.target, b.target), where, "target differs");
}

void compareCase(const Case& c, const fs::path& file) {
  const std::string where = file.string();
  expect(modelComment(file) == fs::path(c.urdfPath).filename().string(), where,
         "the '# model:' comment must name " + fs::path(c.urdfPath).filename().string());
  const Layout b = loadLayout(file.string());
  const Layout& a = c.layout;
  expect(a.floatingBase == b.floatingBase, where, "base differs");
  expect(a.hasGravity == b.hasGravity && a.gravity == b.gravity, where, "gravity differs");
  expect(a.mu == b.mu, where, "mu differs");
  expect(a.iterations == b.iterations, where, "iterations differ");
  expect(a.constraints.size() == b.constraints.size(), where, "number of constraints differs");
  for (std::size_t k = 0; k < a.constraints.size() && k < b.constraints.size(); ++k)
    compareConstraint(a.constraints[k], b.constraints[k], where + ": constraints[" + std::to_string(k) + "]");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s CASES_YAML LAYOUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const fs::path dir = argv[2];
    std::set<std::string> names;
    for (const Case& c : loadCases(argv[1])) {
      names.insert(c.name);
      const fs::path file = dir / (c.name + ".yaml");
      expect(fs::exists(file), file.string(), "missing: every case needs a layout file");
      if (fs::exists(file)) compareCase(c, file);
    }
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".yaml")
        expect(names.count(entry.path().stem().string()) == 1, entry.path().string(), "no such case in cases.yaml");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  if (failures == 0) std::printf("bench layouts match %s\n", argv[1]);
  return failures == 0 ? 0 : 1;
}

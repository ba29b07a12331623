#include "synthetic.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "model/error.hpp"

namespace proxgen::bench {

const char* shapeName(Shape s) { return s == Shape::Chain ? "chain" : "tree"; }

namespace {

int parentOf(Shape shape, int k) { return shape == Shape::Chain ? k - 1 : k / 2; }

std::string linkName(int k) { return k == 0 ? "base" : fmt::format("b{}", k); }

// Axes cycle through z, y, x so that no chain is planar (a planar chain would
// make some contact rows exactly dependent).
const char* axisOf(int k) {
  static const char* axes[] = {"0 0 1", "0 1 0", "1 0 0"};
  return axes[k % 3];
}

// Tree children sit left and right of their parent, chain links one above the other.
std::string originOf(Shape shape, int k) {
  if (shape == Shape::Chain) return "0 0 0.1";
  return k % 2 == 0 ? "0.1 0.05 0" : "0.1 -0.05 0";
}

// Bodies carrying the contacts: `count` distinct bodies evenly spread over the
// candidates (the chain's bodies from the tip down, or the tree's leaves).
std::vector<int> contactBodies(Shape shape, int n, int count) {
  std::vector<int> candidates;
  if (shape == Shape::Chain)
    for (int k = n; k >= 1; --k) candidates.push_back(k);
  else
    for (int k = n / 2 + 1; k <= n; ++k) candidates.push_back(k);  // heap leaves
  if (count > int(candidates.size()))
    throw Error(fmt::format("synthetic {} of {} bodies has room for {} contacts, not {}", shapeName(shape), n,
                            candidates.size(), count));
  std::vector<int> out;
  for (int i = 0; i < count; ++i) out.push_back(candidates[std::size_t(i) * candidates.size() / std::size_t(count)]);
  return out;
}

}  // namespace

std::string syntheticUrdf(Shape shape, int n) {
  std::string s = fmt::format("<?xml version=\"1.0\"?>\n<robot name=\"{}_{}\">\n", shapeName(shape), n);
  s += "  <link name=\"base\"/>\n";
  for (int k = 1; k <= n; ++k) {
    s += fmt::format(
        "  <link name=\"{0}\">\n"
        "    <inertial><origin xyz=\"0 0 0.05\"/><mass value=\"1.0\"/>\n"
        "      <inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.005\"/></inertial>\n"
        "  </link>\n"
        "  <joint name=\"j{1}\" type=\"revolute\">\n"
        "    <parent link=\"{2}\"/><child link=\"{0}\"/>\n"
        "    <origin xyz=\"{3}\"/><axis xyz=\"{4}\"/>\n"
        "    <limit lower=\"-1\" upper=\"1\" effort=\"100\" velocity=\"10\"/>\n"
        "  </joint>\n",
        linkName(k), k, linkName(parentOf(shape, k)), originOf(shape, k), axisOf(k));
  }
  s += "</robot>\n";
  return s;
}

std::string syntheticLayout(Shape shape, int n, int contacts) {
  std::string s = fmt::format("# {} of {} revolute joints, {} point contacts\nbase: fixed\nconstraints:\n",
                              shapeName(shape), n, contacts);
  for (int k : contactBodies(shape, n, contacts))
    s += fmt::format("  - {{name: contact_b{0}, link: b{0}, type: 3d}}\n", k);
  return s;
}

void writeSynthetic(const std::string& dir, Shape shape, int n, int contacts, std::string& urdfPath,
                    std::string& layoutPath) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  urdfPath = (fs::path(dir) / fmt::format("{}_n{}.urdf", shapeName(shape), n)).string();
  layoutPath = (fs::path(dir) / fmt::format("{}_n{}_c{}.yaml", shapeName(shape), n, contacts)).string();
  const auto write = [](const std::string& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    if (!out) throw Error(path + ": cannot write");
  };
  write(urdfPath, syntheticUrdf(shape, n));
  write(layoutPath, syntheticLayout(shape, n, contacts));
}

}  // namespace proxgen::bench

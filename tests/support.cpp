#include "support.hpp"

#include <fmt/format.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "emit/generate.hpp"
#include "model/layout.hpp"

namespace proxgen::test {

std::string modelsDir() {
  const std::string dir = PROXGEN_TEST_MODELS_DIR;
  return std::filesystem::exists(std::filesystem::path(dir) / "cases.yaml") ? dir : "";
}

bool underCi() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

std::vector<Case> sharedCases() {
  if (modelsDir().empty()) return {};
  std::vector<Case> cases = loadCases(modelsDir() + "/cases.yaml");
  // The loops over the cases would otherwise pass with no check at all.
  if (cases.empty()) ADD_FAILURE() << modelsDir() << "/cases.yaml lists no case";
  return cases;
}

std::string modelPath(const std::string& file) { return modelsDir() + "/" + file; }

std::string sourceDir() { return PROXGEN_TEST_SOURCE_DIR; }

std::string syntheticTreeUrdf(int links, int branching, const std::string& pad) {
  std::string xml = "<?xml version=\"1.0\"?>\n<robot name=\"synthetic\">\n";
  const auto link = [](int i) {
    return fmt::format(
        "<link name=\"l{}\"><inertial><origin xyz=\"0 0 0.05\"/><mass value=\"1\"/>"
        "<inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>\n",
        i);
  };
  const char* axes[] = {"1 0 0", "0 1 0", "0 0 1"};
  xml += link(0);
  for (int i = 1; i < links; ++i) {
    xml += fmt::format(
        "<joint name=\"j{}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{}\"/>"
        "<origin xyz=\"0 0 0.1\"/><axis xyz=\"{}\"/><limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/></joint>\n",
        i, (i - 1) / branching, i, axes[i % 3]);
    xml += link(i);
  }
  return xml + pad + "</robot>\n";
}

emit::SolverFiles syntheticChainFiles(int links, const std::string& functions, const std::string& constraints) {
  const TempFile urdf("chain.urdf"), layout("fixed.yaml");
  urdf.write(syntheticTreeUrdf(links, 1));
  layout.write(constraints.empty() ? "base: fixed\n" : "base: fixed\nconstraints:\n  " + constraints + "\n");
  emit::GenerateOptions g;
  g.urdf = urdf.path();
  g.layout = layout.path();
  g.name = "chain";
  g.functions = functions;
  return emit::generateFiles(g);
}

double relErr(const VecX& a, const VecX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

long occurrences(const std::string& text, const std::string& what) {
  long n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string shellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

ProcessResult runProgram(const std::string& program, const std::vector<std::string>& args) {
  const TempFile out(".out"), err(".err");
  std::string cmd = shellQuoted(program);
  for (const std::string& a : args) cmd += " " + shellQuoted(a);
  cmd += " >" + shellQuoted(out.path()) + " 2>" + shellQuoted(err.path());
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out.path()), slurp(err.path())};
}

TempFile::TempFile(const std::string& suffix) {
  static std::atomic<int> counter{0};
  path_ = (std::filesystem::temp_directory_path() /
           ("proxgen_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" + suffix))
              .string();
}

TempFile::~TempFile() {
  std::error_code ec;
  std::filesystem::remove(path_, ec);
}

const std::string& TempFile::write(const std::string& text) const {
  std::ofstream(path_, std::ios::binary) << text;
  return path_;
}

const std::string& TempFile::sized(std::uintmax_t bytes) const {
  std::ofstream(path_, std::ios::binary).put('x');
  std::filesystem::resize_file(path_, bytes);
  return path_;
}

std::vector<NamedSystem> sharedAndRepositorySystems() {
  std::vector<NamedSystem> out;
  for (const Case& c : sharedCases()) out.push_back({c.name, loadCaseSystem(c)});
  const std::string src = sourceDir();
  const auto add = [&](const std::string& name, const std::string& urdf, const std::string& layout) {
    out.push_back({name, loadSystem(src + "/" + urdf, src + "/" + layout)});
  };
  add("example arm", "generated/arm/arm.urdf", "generated/arm/layout.yaml");
  add("example quadruped", "generated/quadruped/quadruped.urdf", "generated/quadruped/layout.yaml");
  add("example humanoid", "generated/humanoid/humanoid.urdf", "generated/humanoid/layout.yaml");
  add("quadruped stand (gains)", "generated/quadruped/quadruped.urdf", "examples/python/quadruped_stand.yaml");
  add("floating arm gains", "tests/data/analytic/floating_arm.urdf", "tests/data/analytic/floating_arm_gains.yaml");
  add("floating arm two welds", "tests/data/analytic/floating_arm.urdf", "tests/data/analytic/floating_arm_two_welds.yaml");
  add("box four corners", "tests/data/analytic/box.urdf", "tests/data/analytic/box_4_corners.yaml");
  return out;
}

}  // namespace proxgen::test

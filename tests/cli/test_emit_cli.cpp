// `proxgen generate` as a user runs it (the binary): bad input gets the
// loaders' one-line errors and leaves nothing in --out; good input writes
// exactly NAME.hpp and NAME.cpp (creating --out), nothing else. `proxgen
// verify` passes on good input and fails when the tolerance is below round-off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "support.hpp"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code = -1;
  std::string output;  // stdout and stderr
};

std::string binary() {
  const char* dir = std::getenv("PROXGEN_BINARY");  // set by tests/CMakeLists.txt: the build's generator/
  return dir ? std::string(dir) + "/proxgen" : "";
}

Outcome runCommand(const std::string& command, const std::string& args) {
  Outcome r;
  FILE* p = popen((binary() + " " + command + " " + args + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.output += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

Outcome run(const std::string& args) { return runCommand("generate", args); }

int countOf(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> out;
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

class GenerateCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (binary().empty() || !fs::exists(binary())) GTEST_SKIP() << "no proxgen binary (PROXGEN_BINARY)";
    tmp_ = fs::temp_directory_path() / ("proxgen_test_emit_cli_" + std::to_string(::getpid()));
    fs::remove_all(tmp_);
    fs::create_directories(tmp_);
  }
  void TearDown() override { fs::remove_all(tmp_); }
  fs::path tmp_;
  const std::string data_ = PROXGEN_TEST_DATA_DIR;
  const std::string arm_ = proxgen::test::sourceDir() + "/generated/arm";
};

TEST_F(GenerateCommand, WritesTheSolverAndItsCInterfaceAndCreatesTheFolder) {
  const fs::path out = tmp_ / "new" / "folder";
  const Outcome r = run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + out.string() + " --name arm");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(listing(out), (std::set<std::string>{"arm.hpp", "arm.cpp", "arm_c.h", "arm_c.cpp"}));
  // Again into the same folder: replaced, still nothing else (no temporary left).
  ASSERT_EQ(run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + out.string() + " --name arm").code, 0);
  EXPECT_EQ(listing(out), (std::set<std::string>{"arm.hpp", "arm.cpp", "arm_c.h", "arm_c.cpp"}));
}

TEST_F(GenerateCommand, TheNameIsSanitised) {
  const Outcome r = run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + tmp_.string() +
                    " --name '../../evil name'");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(listing(tmp_), (std::set<std::string>{"evil_name.hpp", "evil_name.cpp", "evil_name_c.h", "evil_name_c.cpp"}));
}

// Each bad input: exit code 1, one "proxgen: error:" line naming the file,
// and no output folder (nor anything in an existing one).
TEST_F(GenerateCommand, BadInputLeavesNothing) {
  struct Bad {
    std::string args, mentions;
  };
  const std::string good = data_ + "/good/arm3.urdf";
  const std::vector<Bad> bad = {
      {data_ + "/bad/not_xml.urdf --layout " + data_ + "/good/arm3_tool.yaml", "not_xml.urdf"},
      {data_ + "/bad/zero_axis.urdf --layout " + data_ + "/good/arm3_tool.yaml", "zero_axis.urdf"},
      {good + " --layout " + data_ + "/bad/unknown_link.yaml", "unknown_link.yaml"},
      {good + " --layout " + data_ + "/bad/malformed.yaml", "malformed.yaml"},
      {good + " --layout " + data_ + "/bad/mu_negative.yaml", "mu_negative.yaml"},
      {good + " --layout " + tmp_.string() + "/missing.yaml", "missing.yaml"},
      {"--cases " + data_ + "/good/arm3_tool.yaml --case nothing", "arm3_tool.yaml"},
  };
  const fs::path existing = tmp_ / "existing";
  fs::create_directories(existing);
  for (const Bad& b : bad) {
    const fs::path fresh = tmp_ / "fresh";
    for (const fs::path& out : {fresh, existing}) {
      const Outcome r = run(b.args + " --out " + out.string());
      EXPECT_EQ(r.code, 1) << b.args << "\n" << r.output;
      EXPECT_EQ(r.output.rfind("proxgen: error: ", 0), 0u) << r.output;
      EXPECT_NE(r.output.find(b.mentions), std::string::npos) << r.output;
      EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
    }
    EXPECT_FALSE(fs::exists(fresh)) << b.args;
    EXPECT_TRUE(listing(existing).empty()) << b.args;
  }
}

TEST_F(GenerateCommand, BadOptionsLeaveNothing) {
  const fs::path out = tmp_ / "out";
  EXPECT_NE(run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + out.string() + " --scalar half").code, 0);
  EXPECT_NE(run(arm_ + "/arm.urdf --out " + out.string()).code, 0);  // no layout
  EXPECT_FALSE(fs::exists(out));
  // --out naming a file.
  const fs::path file = tmp_ / "a_file";
  { std::FILE* f = std::fopen(file.c_str(), "w"); std::fclose(f); }
  const Outcome r = run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + file.string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("not a folder"), std::string::npos) << r.output;
}

// --functions with a name that is no function: one line naming the valid ones, nothing written.
TEST_F(GenerateCommand, AnUnknownFunctionIsOneLineNamingTheValidOnes) {
  const fs::path out = tmp_ / "out";
  const Outcome r = run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + out.string() + " --functions rnea");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output.rfind("proxgen: error: ", 0), 0u) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
  for (const char* part : {"--functions", "'rnea'", "inverse_dynamics", "mass_matrix"})
    EXPECT_NE(r.output.find(part), std::string::npos) << part << " not in: " << r.output;
  EXPECT_FALSE(fs::exists(out));
  // The same from a layout: its file, line and element.
  const fs::path layout = tmp_ / "functions.yaml";
  { std::FILE* f = std::fopen(layout.c_str(), "w"); std::fputs("functions: [mass_matrix, rnea]\n", f); std::fclose(f); }
  const Outcome l = run(arm_ + "/arm.urdf --layout " + layout.string() + " --out " + out.string());
  EXPECT_EQ(l.code, 1) << l.output;
  for (const char* part : {"functions.yaml:1", "functions[1]", "'rnea'", "constrained_aba"})
    EXPECT_NE(l.output.find(part), std::string::npos) << part << " not in: " << l.output;
  EXPECT_FALSE(fs::exists(out));
}

// The Python module binds what the solver holds: with the mass matrix alone,
// its binding and no solver's (tests/python/test_module_functions.py imports
// such a module).
TEST_F(GenerateCommand, PythonModuleBindsTheFunctionsTheSolverHolds) {
  const fs::path out = tmp_ / "out";
  const Outcome r =
      run(arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --out " + out.string() + " --python --functions mass_matrix");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string module = proxgen::test::slurp((out / "arm_python.cpp").string());
  EXPECT_NE(module.find("bindMatrixOfQ<Solver>(m, kInfo, \"mass_matrix\", &arm::mass_matrix"), std::string::npos) << module;
  EXPECT_EQ(module.find("bindSolve<"), std::string::npos) << module;
  EXPECT_NE(module.find("m.attr(\"functions\") = pybind11::make_tuple(\n      \"mass_matrix\");"), std::string::npos) << module;
}

// verify covers the functions it is asked for: here two joint-space ones and
// no solver (one line each, no solver lines), and fails them below round-off.
TEST_F(GenerateCommand, VerifyCoversTheFunctionsAskedFor) {
  const std::string inputs = arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --samples 3 --functions mass_matrix,inverse_dynamics";
  const Outcome ok = runCommand("verify", inputs);
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_EQ(countOf(ok.output, "  ok\n"), 2) << ok.output;
  EXPECT_EQ(countOf(ok.output, "mass_matrix M "), 1) << ok.output;
  EXPECT_EQ(countOf(ok.output, "inverse_dynamics tau "), 1) << ok.output;
  EXPECT_EQ(countOf(ok.output, "constrained_aba"), 0) << ok.output;
  const Outcome strict = runCommand("verify", inputs + " --tolerance 1e-300");
  EXPECT_EQ(strict.code, 1) << strict.output;
  EXPECT_GE(countOf(strict.output, "  FAIL\n"), 1) << strict.output;  // an exact 0 error would pass
}

// `proxgen verify` generates, compiles (with the compiler proxgen was built
// with: a few seconds for the arm) and compares with the generic solvers.
TEST_F(GenerateCommand, VerifyPassesOnTheArmAndFailsBelowRoundoff) {
  const std::string inputs = arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --samples 3";
  const Outcome ok = runCommand("verify", inputs);
  EXPECT_EQ(ok.code, 0) << ok.output;
  // Judged by the conditioning-aware bounds of verify/compare.hpp (the
  // generated-solver tests' bounds), not a flat tolerance.
  EXPECT_NE(ok.output.find("PASSED: bounds c n u kappa"), std::string::npos) << ok.output;
  // 2 algorithms x (qdd, lambda) x K in {1, 2, 3, converged}, each judged.
  EXPECT_EQ(countOf(ok.output, "  ok\n"), 16) << ok.output;
  // A tolerance below round-off (the arm's proxPV differs by ~1e-11): the same
  // comparison fails, says which lines, and exits 1.
  const Outcome strict = runCommand("verify", inputs + " --tolerance 1e-300");
  EXPECT_EQ(strict.code, 1) << strict.output;
  EXPECT_GT(countOf(strict.output, "  FAIL\n"), 0) << strict.output;
  EXPECT_NE(strict.output.find("FAILED: tolerance 1e-300"), std::string::npos) << strict.output;
}

TEST_F(GenerateCommand, VerifyOneSharedCase) {
  PROXGEN_REQUIRE_MODELS();
  const std::string cases = proxgen::test::modelsDir() + "/cases.yaml";
  const Outcome ok = runCommand("verify", "--cases " + cases + " --case iiwa_h3 --samples 3");
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_NE(ok.output.find("case iiwa_h3 of"), std::string::npos) << ok.output;
  EXPECT_EQ(countOf(ok.output, "  ok\n"), 16) << ok.output;
  const Outcome missing = runCommand("verify", "--cases " + cases + " --case no_such_case");
  EXPECT_EQ(missing.code, 1) << missing.output;
  EXPECT_NE(missing.output.find("no case named 'no_such_case'"), std::string::npos) << missing.output;
  const Outcome mixed = runCommand("verify", arm_ + "/arm.urdf --cases " + cases + " --case iiwa_h3");
  EXPECT_EQ(mixed.code, 1) << mixed.output;
  EXPECT_NE(mixed.output.find("--cases and --case go together"), std::string::npos) << mixed.output;
}

}  // namespace

// Determinism and locale independence (issue 7, docs/guarantees.md).
//
// `proxgen generate` must write the same bytes whatever the working directory
// and the locale, and every number proxgen reads or prints must mean the same
// in a locale whose decimal point is a comma. The comma locale is de_DE.UTF-8,
// compiled by the test itself with `localedef` (Debian package `locales`) into
// a private folder named by LOCPATH, so no system locale needs installing. In
// CI (CI=true) a missing `localedef` is a failure; elsewhere the tests skip.
#include <gtest/gtest.h>

#include <clocale>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <locale>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "emit/generate.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

namespace fs = std::filesystem;

constexpr const char* kComma = "de_DE.UTF-8";

using test::slurp;

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class Determinism : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("proxgen_test_determinism_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "locales");
    // A locale with a comma decimal point, built where only this test looks.
    const std::string def = "localedef -i de_DE -f UTF-8 '" + (root_ / "locales" / kComma).string() + "' > /dev/null 2>&1";
    haveLocale_ = shell(def) == 0 && fs::exists(root_ / "locales" / kComma);
    // ... and it does print a comma in a child process started as proxgen is below.
    const fs::path probe = root_ / "probe.txt";
    shell("LOCPATH='" + (root_ / "locales").string() + "' LC_ALL=" + kComma + " /usr/bin/printf '%.1f' 0.5 > '" +
          probe.string() + "' 2>/dev/null");
    haveLocale_ = haveLocale_ && slurp(probe) == "0,5";
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  void SetUp() override {
    if (haveLocale_) return;
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL() << "CI: cannot build the de_DE.UTF-8 locale (apt-get install locales)";
    GTEST_SKIP() << "needs localedef and the de_DE locale source (Debian package `locales`)";
  }

  // Runs the proxgen binary in `cwd` with LC_ALL = locale; stdout to `out`.
  static int proxgen(const fs::path& cwd, const std::string& locale, const std::string& args, const fs::path& out) {
    return shell("cd '" + cwd.string() + "' && LOCPATH='" + (root_ / "locales").string() + "' LC_ALL=" + locale + " '" +
                 PROXGEN_BINARY_PATH + "' " + args + " > '" + out.string() + "' 2>&1");
  }

  static inline fs::path root_;
  static inline bool haveLocale_ = false;
  const std::string arm_ = test::sourceDir() + "/generated/arm";
};

// Two runs, different working directories and locales: the same bytes.
TEST_F(Determinism, GenerateIsByteIdenticalAcrossFoldersAndLocales) {
  const fs::path a = root_ / "run_a", b = root_ / "deeper" / "run_b";
  fs::create_directories(a);
  fs::create_directories(b);
  const std::string inputs = arm_ + "/arm.urdf --layout " + arm_ + "/layout.yaml --name arm";
  ASSERT_EQ(proxgen(a, "C", "generate " + inputs + " --out out", a / "log"), 0) << slurp(a / "log");
  ASSERT_EQ(proxgen(b, kComma, "generate " + inputs + " --out out", b / "log"), 0) << slurp(b / "log");
  for (const char* file : {"arm.hpp", "arm.cpp"}) {
    const std::string first = slurp(a / "out" / file), second = slurp(b / "out" / file);
    ASSERT_FALSE(first.empty()) << file;
    EXPECT_EQ(first, second) << file << " differs between LC_ALL=C in " << a << " and LC_ALL=" << kComma << " in " << b;
    // And both are the checked-in solver (itself tested fresh).
    EXPECT_EQ(first, slurp(fs::path(arm_) / file)) << file;
  }
}

// The numbers printed by check and eval are the same text in both locales.
TEST_F(Determinism, PrintedNumbersDoNotFollowTheLocale) {
  const std::string data = PROXGEN_TEST_DATA_DIR;
  const std::string eval = "eval " + data + "/good/arm3.urdf --layout " + data + "/good/arm3_tool.yaml --state " + data +
                           "/good/arm3_state.json --algorithm pv";
  const std::string check = "check " + data + "/good/arm3.urdf --layout " + data + "/good/arm3_tool.yaml";
  for (const std::string& args : {eval, check, check + " --json"}) {
    ASSERT_EQ(proxgen(root_, "C", args, root_ / "c.txt"), 0) << slurp(root_ / "c.txt");
    ASSERT_EQ(proxgen(root_, kComma, args, root_ / "de.txt"), 0) << slurp(root_ / "de.txt");
    const std::string c = slurp(root_ / "c.txt");
    EXPECT_NE(c.find('.'), std::string::npos) << args << ": no decimal number printed?\n" << c;
    EXPECT_EQ(c, slurp(root_ / "de.txt")) << args;
  }
}

// A program that links proxgen and sets a comma locale for itself (as a GUI or
// a ROS node may): parsing and generation still read "0.5" as one half.
TEST_F(Determinism, TheLibraryIgnoresTheProcessLocale) {
  emit::GenerateOptions g;
  g.urdf = arm_ + "/arm.urdf";
  g.layout = arm_ + "/layout.yaml";
  g.name = "arm";
  const std::string data = PROXGEN_TEST_DATA_DIR;
  const std::string urdf = data + "/good/arm3.urdf", layout = data + "/good/arm3_tool.yaml";
  const std::string stateFile = data + "/good/arm3_state.json";
  const emit::SolverFiles classic = emit::generateFiles(g);
  const System sysClassic = loadSystem(urdf, layout);
  const std::vector<State> statesClassic = loadStates(sysClassic.model, stateFile);

  ::setenv("LOCPATH", (root_ / "locales").c_str(), 1);
  ASSERT_NE(std::setlocale(LC_ALL, kComma), nullptr);
  const std::locale previous = std::locale::global(std::locale(kComma));
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%.1f", 0.5);
  const std::string printed = buffer;  // proves the locale took effect

  const emit::SolverFiles comma = emit::generateFiles(g);
  const System sysComma = loadSystem(urdf, layout);
  const std::vector<State> statesComma = loadStates(sysComma.model, stateFile);

  std::locale::global(previous);
  std::setlocale(LC_ALL, "C");
  ::unsetenv("LOCPATH");

  EXPECT_EQ(printed, "0,5") << "the comma locale did not take effect, so this test proves nothing";
  EXPECT_EQ(classic.header, comma.header);
  EXPECT_EQ(classic.source, comma.source);
  EXPECT_EQ(sysClassic.mu, sysComma.mu);
  EXPECT_EQ(sysClassic.model.gravity, sysComma.model.gravity);
  ASSERT_EQ(sysClassic.model.bodies.size(), sysComma.model.bodies.size());
  for (std::size_t i = 0; i < sysClassic.model.bodies.size(); ++i)
    EXPECT_EQ(sysClassic.model.bodies[i].inertia.mass, sysComma.model.bodies[i].inertia.mass) << "body " << i;
  for (std::size_t i = 0; i < sysClassic.constraints.size(); ++i)
    EXPECT_EQ(sysClassic.constraints[i].placement.p, sysComma.constraints[i].placement.p) << "constraint " << i;
  ASSERT_EQ(statesClassic.size(), statesComma.size());
  for (std::size_t k = 0; k < statesClassic.size(); ++k) {
    EXPECT_EQ(statesClassic[k].q, statesComma[k].q);
    EXPECT_EQ(statesClassic[k].v, statesComma[k].v);
    EXPECT_EQ(statesClassic[k].tau, statesComma[k].tau);
  }
}

}  // namespace
}  // namespace proxgen

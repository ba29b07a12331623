// proxgen warns, when float is asked for (`generate` and `verify` with --scalar float,
// `check --scalar float`), that a layout would make a float constrainedABA lose accuracy:
// it folds the penalty mu (a mass) into the inertia of every body on the constraint support,
// and a float keeps the lightest one's own inertia only to u mu / m (u = 2^-24). The warning
// fires above u mu / m = 1e-3 (docs/embedded.md, "Float accuracy": the measured float errors of
// the generated solvers under qemu were 0.05 to 12 times this estimate at mu = 1e4).
//
// Without float asked for, it says nothing (issue 13 item 6: the demo's first
// command, a `check` of a double user, printed it).
//
// The expected numbers are derived here from the model (lightest support body, its mass), not
// copied from the binary's output. Inputs: the repository's example quadruped (always present).
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

constexpr double kU = 0x1p-24;        // float unit roundoff
constexpr double kThreshold = 1e-3;   // the warning's criterion on kU * mu / m

using test::ProcessResult;
using test::slurp;
using test::TempFile;

ProcessResult runProxgen(const std::vector<std::string>& args) { return test::runProgram(PROXGEN_BINARY_PATH, args); }

const std::string kUrdf = test::sourceDir() + "/generated/quadruped/quadruped.urdf";
const std::string kLayout = test::sourceDir() + "/generated/quadruped/layout.yaml";

/// The example's layout with its `mu:` replaced, in a temporary file removed by the fixture.
class FloatWarning : public ::testing::Test {
 protected:
  std::string layoutWithMu(double mu) {
    const std::string text = std::regex_replace(slurp(kLayout), std::regex("\nmu:[^\n]*"), fmt::format("\nmu: {}", mu));
    EXPECT_NE(text.find(fmt::format("\nmu: {}", mu)), std::string::npos) << "the example layout has no mu line";
    return temps_.emplace_back(std::make_unique<TempFile>(".yaml"))->write(text);
  }

  // The lightest body with mass on the constraint support, from the library.
  void SetUp() override {
    const System sys = loadSystem(kUrdf, kLayout);
    for (int b : sys.supportBodies()) {
      const Body& body = sys.model.bodies[std::size_t(b)];
      if (b > 0 && body.inertia.mass > 0 && (mass_ == 0 || body.inertia.mass < mass_)) {
        mass_ = body.inertia.mass;
        link_ = body.link;
      }
    }
    ASSERT_GT(mass_, 0);
    layoutMu_ = sys.mu;
  }
  /// mu at which kU * mu / m equals the threshold.
  double muAtThreshold() const { return kThreshold * mass_ / kU; }

  std::vector<std::unique_ptr<TempFile>> temps_;  // removed with the fixture
  double mass_ = 0, layoutMu_ = 0;
  std::string link_;
};

// 10 % above the threshold: warns, names the body and gives the estimate.
TEST_F(FloatWarning, WarnsAboveTheThreshold) {
  const double mu = 1.1 * muAtThreshold();
  const ProcessResult r = runProxgen({"check", kUrdf, "--layout", layoutWithMu(mu), "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("proxgen: warning:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'" + link_ + "'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(fmt::format("{:.1e}", kU * mu / mass_)), std::string::npos) << r.err;  // 1.1e-03
  EXPECT_NE(r.err.find("prox_pv"), std::string::npos) << "the warning must say what to do:\n" << r.err;
}

// 10 % below: silent.
TEST_F(FloatWarning, SilentBelowTheThreshold) {
  const ProcessResult r = runProxgen({"check", kUrdf, "--layout", layoutWithMu(0.9 * muAtThreshold()), "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("constrained_aba"), std::string::npos) << r.err;
}

// The example quadruped's own layout (mu = 1e4, shanks of 64 g) is above the threshold:
// float constrainedABA lost 1.8e-2 on it under qemu (docs/embedded.md).
TEST_F(FloatWarning, TheExampleQuadrupedsLayoutWarns) {
  ASSERT_GT(kU * layoutMu_ / mass_, kThreshold);
  const ProcessResult r = runProxgen({"check", kUrdf, "--layout", kLayout, "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(fmt::format("{:.1e}", kU * layoutMu_ / mass_)), std::string::npos) << r.err;
}

// The same layout, float not asked for: check (the demo's first command) and a
// double generate are quiet; a float generate warns, once.
TEST_F(FloatWarning, OnlyWhenFloatIsAskedFor) {
  ASSERT_GT(kU * layoutMu_ / mass_, kThreshold);  // the layout would warn in float
  ProcessResult r = runProxgen({"check", kUrdf, "--layout", kLayout});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("constrained_aba"), std::string::npos) << r.err;
  TempFile out(".out");
  r = runProxgen({"generate", kUrdf, "--layout", kLayout, "--out", out.path()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("constrained_aba"), std::string::npos) << r.err;
  r = runProxgen({"generate", kUrdf, "--layout", kLayout, "--out", out.path(), "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(fmt::format("{:.1e}", kU * layoutMu_ / mass_)), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("proxgen: warning:"), r.err.rfind("proxgen: warning:")) << "once:\n" << r.err;
  std::error_code ec;
  std::filesystem::remove_all(out.path(), ec);
}

// The warning goes to stderr only: --json output stays parseable.
TEST_F(FloatWarning, JsonOnStdoutStaysClean) {
  const ProcessResult r = runProxgen({"check", kUrdf, "--layout", kLayout, "--json", "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("constrained_aba"), std::string::npos) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
}

// Without a layout there are no constraints, no penalty and no warning.
TEST_F(FloatWarning, NoLayoutNoWarning) {
  const ProcessResult r = runProxgen({"check", kUrdf, "--floating", "--scalar", "float"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("constrained_aba"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace proxgen

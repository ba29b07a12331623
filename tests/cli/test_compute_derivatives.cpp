// `proxgen eval --compute derivatives` against the library: the converged
// constrained solution and its six derivative matrices (docs/derivatives.md),
// rows and columns named, must EQUAL constrainedDynamicsDerivatives at the
// same states (the argument of test_compute.cpp: the binary and this test link
// the same proxgen_core, read bit-identical states, and nlohmann prints every
// double the shortest round-trip way), so no tolerance. Then its options and
// the bad inputs it adds.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "algorithms/derivatives.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "compute_json.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using nlohmann::json;
using test::ProcessResult;
using test::TempFile;

using test::dofNames;
using test::expectMatrix;
using test::Robot;
using test::rowNames;

ProcessResult runDerivatives(const Robot& r, const std::string& state, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"eval", r.urdf, "--layout", r.layout, "--state", state, "--compute", "derivatives"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::runProgram(PROXGEN_BINARY_PATH, args);
}

TEST(ComputeDerivatives, EqualsTheLibraryWithNamedRowsAndColumns) {
  for (const Robot& robot : test::exampleRobots()) {
    const System sys = loadSystem(robot.urdf, robot.layout);
    const Model& m = sys.model;
    std::mt19937 rng(51);
    json list = json::array();
    for (int k = 0; k < 2; ++k) {
      const State s = randomState(m, rng);
      list.push_back({{"q", configurationToJson(m, s.q)}, {"v", velocityToJson(m, s.v)}, {"tau", velocityToJson(m, s.tau)}});
    }
    TempFile file(".json");
    file.write(list.dump());
    const std::vector<State> states = loadStates(m, file.path());  // what the binary reads
    // Default: the layout's mu and the converged solve (K = 200); then both given.
    for (const auto& [extra, mu, K] : {std::tuple<std::vector<std::string>, double, int>{{}, sys.mu, 200},
                                      {{"--mu", "250", "--iterations", "7"}, 250.0, 7}}) {
      const ProcessResult p = runDerivatives(robot, file.path(), extra);
      ASSERT_EQ(p.code, 0) << p.err;
      const json out = json::parse(p.out);
      ASSERT_EQ(out.size(), states.size());
      Data d(sys);
      DerivativeData dd(sys);
      for (std::size_t k = 0; k < states.size(); ++k) {
        const json& r = out[k];
        const std::string what = robot.layout + " state " + std::to_string(k) + " K " + std::to_string(K);
        constrainedDynamicsDerivatives(sys, d, dd, states[k].q, states[k].v, states[k].tau, mu, K);
        EXPECT_EQ(r.at("compute"), "derivatives");
        EXPECT_EQ(r.at("mu").get<double>(), mu) << what;
        EXPECT_EQ(r.at("iterations").get<int>(), K) << what;
        EXPECT_EQ(velocityFromJson(m, r.at("qdd"), "qdd", false), dd.qdd) << what;
        for (const Constraint& c : sys.constraints)
          for (int row = 0; row < c.rows(); ++row)
            EXPECT_EQ(r.at("lambda").at(c.name)[row].get<double>(), dd.lambda[c.row + row]) << what << " " << c.name;
        const std::vector<std::string> dofs = dofNames(m), rows = rowNames(sys);
        expectMatrix(r.at("dqdd_dq"), dd.dqdd_dq, dofs, dofs, what + " dqdd_dq");
        expectMatrix(r.at("dqdd_dv"), dd.dqdd_dv, dofs, dofs, what + " dqdd_dv");
        expectMatrix(r.at("dqdd_dtau"), dd.dqdd_dtau, dofs, dofs, what + " dqdd_dtau");
        expectMatrix(r.at("dlambda_dq"), dd.dlambda_dq, rows, dofs, what + " dlambda_dq");
        expectMatrix(r.at("dlambda_dv"), dd.dlambda_dv, rows, dofs, what + " dlambda_dv");
        expectMatrix(r.at("dlambda_dtau"), dd.dlambda_dtau, rows, dofs, what + " dlambda_dtau");
      }
    }
  }
}

// One line naming the element, exit 1, nothing on stdout.
void expectRefused(const ProcessResult& p, const std::string& needle) {
  EXPECT_EQ(p.code, 1);
  EXPECT_EQ(p.out, "");
  EXPECT_NE(p.err.find(needle), std::string::npos) << p.err;
  EXPECT_EQ(std::count(p.err.begin(), p.err.end(), '\n'), 1) << p.err;
}

TEST(ComputeDerivatives, RefusesWhatDoesNotApply) {
  const Robot arm = test::exampleRobots().front();
  const System sys = loadSystem(arm.urdf, arm.layout);
  std::mt19937 rng(52);
  const State s = randomState(sys.model, rng);
  json state = {{"q", configurationToJson(sys.model, s.q)}, {"v", velocityToJson(sys.model, s.v)}};
  TempFile file(".json");
  file.write(state.dump());
  // --iterations sets the derivatives' solve only; elsewhere it is refused, not ignored.
  expectRefused(test::runProgram(PROXGEN_BINARY_PATH, {"eval", arm.urdf, "--layout", arm.layout, "--state", file.path(),
                                                       "--compute", "mass_matrix", "--iterations", "5"}),
                "--iterations");
  expectRefused(runDerivatives(arm, file.path(), {"--iterations", "-3"}), "--iterations");
  // The state's qdd belongs to inverse_dynamics.
  state["qdd"] = velocityToJson(sys.model, s.v);
  file.write(state.dump());
  expectRefused(runDerivatives(arm, file.path(), {}), "qdd");
}

}  // namespace
}  // namespace proxgen

// `proxgen eval --compute QUANTITY` against the library: every quantity of the
// dynamics library (docs/dynamics.md), printed keyed by joint and constraint
// names, must EQUAL the library's value (the argument of test_cli.cpp: the
// binary and this test link the same proxgen_core, read bit-identical states,
// and nlohmann prints every double the shortest round-trip way), so no
// tolerance is allowed. Then the bad inputs --compute adds.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "compute_json.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using nlohmann::json;
using test::ProcessResult;
using test::TempFile;

ProcessResult runProxgen(const std::vector<std::string>& args) { return test::runProgram(PROXGEN_BINARY_PATH, args); }

using test::dofNames;
using test::expectMatrix;
using test::Robot;
using test::rowNames;

json stateJson(const Model& m, const State& s) {
  return {{"q", configurationToJson(m, s.q)}, {"v", velocityToJson(m, s.v)}, {"tau", velocityToJson(m, s.tau)}};
}

// Joint-keyed vector: a number per one-dof joint, a list for the free flyer.
void expectJoints(const Model& m, const json& j, const VecX& x, const std::string& what) {
  ASSERT_EQ(j.size(), std::size_t(m.numBodies() - 1)) << what;
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& jt = m.bodies[i].joint;
    const json& e = j.at(jt.name);
    if (jt.nv == 1) {
      EXPECT_EQ(e.get<double>(), x[jt.idx_v]) << what << " " << jt.name;
      continue;
    }
    ASSERT_EQ(e.size(), std::size_t(jt.nv));
    for (int k = 0; k < jt.nv; ++k) EXPECT_EQ(e[k].get<double>(), x[jt.idx_v + k]) << what << " " << jt.name << "[" << k << "]";
  }
}

json runCompute(const Robot& r, const std::string& state, const std::string& quantity, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {"eval", r.urdf, "--layout", r.layout, "--state", state, "--compute", quantity};
  args.insert(args.end(), extra.begin(), extra.end());
  const ProcessResult p = runProxgen(args);
  EXPECT_EQ(p.code, 0) << quantity << ": " << p.err;
  try {
    return json::parse(p.out);
  } catch (const json::exception& e) {
    ADD_FAILURE() << quantity << ": stdout is not JSON: " << e.what();
    return json::array();
  }
}

TEST(Compute, EveryQuantityEqualsTheLibrary) {
  for (const Robot& robot : test::exampleRobots()) {
    const System sys = loadSystem(robot.urdf, robot.layout);
    const Model& m = sys.model;
    std::mt19937 rng(41);
    json list = json::array();
    for (int k = 0; k < 2; ++k) list.push_back(stateJson(m, randomState(m, rng)));
    TempFile file(".json");
    file.write(list.dump());
    const std::vector<State> states = loadStates(m, file.path());  // what the binary reads

    // inverse_dynamics also reads qdd and lambda from each state object.
    json withForces = list;
    std::vector<VecX> qdds, lambdas;
    for (std::size_t k = 0; k < states.size(); ++k) {
      VecX qdd = VecX::Zero(m.nv), lambda = VecX::Zero(sys.nc);
      for (int i = 0; i < m.nv; ++i) qdd[i] = std::uniform_real_distribution<double>(-1, 1)(rng);
      for (int i = 0; i < sys.nc; ++i) lambda[i] = std::uniform_real_distribution<double>(-50, 50)(rng);
      json lam = json::object();
      for (const Constraint& c : sys.constraints) lam[c.name] = std::vector<double>(lambda.data() + c.row, lambda.data() + c.row + c.rows());
      withForces[k]["qdd"] = velocityToJson(m, qdd);
      withForces[k]["lambda"] = lam;
      qdds.push_back(qdd);
      lambdas.push_back(lambda);
    }
    TempFile forces(".json");
    forces.write(withForces.dump());

    const json id = runCompute(robot, forces.path(), "inverse_dynamics");
    const json h = runCompute(robot, file.path(), "nonlinear_effects");
    const json M = runCompute(robot, file.path(), "mass_matrix");
    const json Minv = runCompute(robot, file.path(), "mass_matrix_inverse");
    const json X = runCompute(robot, file.path(), "placements");
    const json J = runCompute(robot, file.path(), "jacobian");
    const json gamma = runCompute(robot, file.path(), "drift");
    const json G = runCompute(robot, file.path(), "delassus");
    const json Ginv = runCompute(robot, file.path(), "delassus_inverse", {"--mu", "250"});
    const json GinvLayout = runCompute(robot, file.path(), "delassus_inverse");
    for (const json* j : {&id, &h, &M, &Minv, &X, &J, &gamma, &G, &Ginv, &GinvLayout}) ASSERT_EQ(j->size(), states.size());

    Data d(sys);
    for (std::size_t k = 0; k < states.size(); ++k) {
      const State& s = states[k];
      EXPECT_EQ(id[k].at("compute"), "inverse_dynamics");
      expectJoints(m, id[k].at("tau"), inverseDynamics(sys, d, s.q, s.v, qdds[k], &lambdas[k]), "tau");
      expectJoints(m, h[k].at("h"), nonLinearEffects(sys, d, s.q, s.v), "h");
      expectMatrix(M[k].at("M"), crba(sys, d, s.q), dofNames(m), dofNames(m), "M");
      expectMatrix(Minv[k].at("Minv"), massMatrixInverse(sys, d, s.q), dofNames(m), dofNames(m), "Minv");
      const VecX P = constraintPlacements(sys, d, s.q);
      ASSERT_EQ(X[k].at("placements").size(), sys.constraints.size());
      for (std::size_t c = 0; c < sys.constraints.size(); ++c) {
        const json& x = X[k].at("placements").at(sys.constraints[c].name);
        for (int e = 0; e < 9; ++e) EXPECT_EQ(x.at("rotation")[e / 3][e % 3].get<double>(), P[12 * c + e]);
        for (int e = 0; e < 3; ++e) EXPECT_EQ(x.at("position")[e].get<double>(), P[12 * c + 9 + e]);
      }
      expectMatrix(J[k].at("J"), constraintJacobianRows(sys, d, s.q), rowNames(sys), dofNames(m), "J");
      const VecX g = constraintDrift(sys, d, s.q, s.v);
      for (const Constraint& c : sys.constraints)
        for (int r = 0; r < c.rows(); ++r) EXPECT_EQ(gamma[k].at("gamma").at(c.name)[r].get<double>(), g[c.row + r]);
      expectMatrix(G[k].at("G"), delassus(sys, d, s.q), rowNames(sys), rowNames(sys), "G");
      EXPECT_EQ(Ginv[k].at("mu").get<double>(), 250.0);
      expectMatrix(Ginv[k].at("Ginv"), delassusInverse(sys, d, s.q, 250.0), rowNames(sys), rowNames(sys), "Ginv");
      EXPECT_EQ(GinvLayout[k].at("mu").get<double>(), sys.mu);
      expectMatrix(GinvLayout[k].at("Ginv"), delassusInverse(sys, d, s.q, sys.mu), rowNames(sys), rowNames(sys), "Ginv");
    }
  }
}

// wrenches reads lambda (keyed by constraint) and prints, per constraint, the
// force and the torque of constraintWrenches, equal as above.
TEST(Compute, WrenchesEqualTheLibraryKeyedByConstraint) {
  for (const Robot& robot : test::exampleRobots()) {
    const System sys = loadSystem(robot.urdf, robot.layout);
    std::mt19937 rng(43);
    json one = stateJson(sys.model, randomState(sys.model, rng));
    VecX lambda(sys.nc);
    for (int i = 0; i < sys.nc; ++i) lambda[i] = std::uniform_real_distribution<double>(-50, 50)(rng);
    json lam = json::object();
    for (const Constraint& c : sys.constraints) lam[c.name] = std::vector<double>(lambda.data() + c.row, lambda.data() + c.row + c.rows());
    one["lambda"] = lam;
    TempFile file(".json");
    file.write(one.dump());
    const json r = runCompute(robot, file.path(), "wrenches");
    json plain = one;
    plain.erase("lambda");
    TempFile plainFile(".json");
    plainFile.write(plain.dump());
    const State s = loadStates(sys.model, plainFile.path()).at(0);
    Data d(sys);
    const VecX W = constraintWrenches(sys, d, s.q, lambda);
    ASSERT_EQ(r.at("wrenches").size(), sys.constraints.size());
    for (std::size_t c = 0; c < sys.constraints.size(); ++c) {
      const json& x = r.at("wrenches").at(sys.constraints[c].name);
      for (int e = 0; e < 3; ++e) {
        EXPECT_EQ(x.at("force")[e].get<double>(), W[6 * c + e]);
        EXPECT_EQ(x.at("torque")[e].get<double>(), W[6 * c + 3 + e]);
      }
    }
    // Without lambda: one clear line.
    const ProcessResult p = runProxgen({"eval", robot.urdf, "--layout", robot.layout, "--state", plainFile.path(),
                                        "--compute", "wrenches"});
    EXPECT_EQ(p.code, 1);
    EXPECT_NE(p.err.find("lambda: missing"), std::string::npos) << p.err;
  }
}

TEST(Compute, LambdaIsOptionalForInverseDynamics) {
  const Robot robot = test::exampleRobots()[1];
  const System sys = loadSystem(robot.urdf, robot.layout);
  std::mt19937 rng(42);
  json one = stateJson(sys.model, randomState(sys.model, rng));
  one["qdd"] = velocityToJson(sys.model, VecX::Zero(sys.model.nv));
  TempFile file(".json");
  file.write(one.dump());
  const json r = runCompute(robot, file.path(), "inverse_dynamics");
  ASSERT_TRUE(r.is_object()) << "one state object gives one result object";
  Data d(sys);
  json plain = one;
  plain.erase("qdd");
  TempFile plainFile(".json");
  plainFile.write(plain.dump());
  const State s = loadStates(sys.model, plainFile.path()).at(0);
  // qdd = 0 and no forces: inverse dynamics is h.
  expectJoints(sys.model, r.at("tau"), nonLinearEffects(sys, d, s.q, s.v), "tau = h");
}

// Bad input: one line naming the file or option and the element, exit 1, no stdout.
void expectError(const std::vector<std::string>& args, const std::string& needle) {
  const ProcessResult p = runProxgen(args);
  EXPECT_EQ(p.code, 1) << p.err;
  EXPECT_EQ(p.out, "");
  EXPECT_NE(p.err.find(needle), std::string::npos) << p.err;
  EXPECT_EQ(std::count(p.err.begin(), p.err.end(), '\n'), 1) << p.err;
}

TEST(Compute, BadInputGetsOneClearLine) {
  const Robot robot = test::exampleRobots()[1];
  const System sys = loadSystem(robot.urdf, robot.layout);
  std::mt19937 rng(43);
  const json state = stateJson(sys.model, randomState(sys.model, rng));
  TempFile plain(".json");
  plain.write(state.dump());
  const auto args = [&](const std::string& file, const std::string& quantity) {
    return std::vector<std::string>{"eval", robot.urdf, "--layout", robot.layout, "--state", file, "--compute", quantity};
  };
  expectError(args(plain.path(), "mass_matrx"), "--compute: unknown quantity 'mass_matrx' (expected one of inverse_dynamics,");
  expectError(args(plain.path(), "inverse_dynamics"), "qdd: missing");

  json withQdd = state;
  withQdd["qdd"] = velocityToJson(sys.model, VecX::Zero(sys.model.nv));
  TempFile qddFile(".json");
  qddFile.write(withQdd.dump());
  expectError(args(qddFile.path(), "mass_matrix"), "qdd: only --compute inverse_dynamics reads qdd");

  json badLambda = withQdd;
  badLambda["lambda"] = {{"no_such_foot", {1, 2, 3}}};
  TempFile lambdaFile(".json");
  lambdaFile.write(badLambda.dump());
  expectError(args(lambdaFile.path(), "inverse_dynamics"), "lambda.'no_such_foot': no constraint of that name");

  json shortLambda = withQdd;
  shortLambda["lambda"] = {{sys.constraints[0].name, {1, 2}}};
  TempFile shortFile(".json");
  shortFile.write(shortLambda.dump());
  expectError(args(shortFile.path(), "inverse_dynamics"), "expected a list of 3 numbers");

  json missingJoint = withQdd;
  missingJoint["qdd"].erase(sys.model.bodies[2].joint.name);
  TempFile missingFile(".json");
  missingFile.write(missingJoint.dump());
  expectError(args(missingFile.path(), "inverse_dynamics"), "qdd.'" + sys.model.bodies[2].joint.name + "': missing");

  std::vector<std::string> badMu = args(plain.path(), "delassus_inverse");
  badMu.insert(badMu.end(), {"--mu", "-1"});
  expectError(badMu, "--mu");
}

}  // namespace
}  // namespace proxgen

// The `proxgen` binary against the library: `check --json` prints the Model's
// vector layout, and `eval` prints the library's own answers, keyed by joint and
// constraint names.
//
// Why eval's numbers must be EQUAL to the library's, not close: the binary and
// this test link the same proxgen_core objects; the test writes the states with
// nlohmann (shortest decimal that reads back to the same double) and then reads
// the file back with the same loadStates the binary uses, so both solve from
// bit-identical inputs; the binary prints every double the same round-trip way.
// Any difference would be a real bug (a different default, a lost digit, a
// slot in the wrong place), so no tolerance is allowed.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using nlohmann::json;

std::string good(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + file; }

// --- running the binary ------------------------------------------------------

using test::ProcessResult;
using test::TempFile;

ProcessResult runProxgen(const std::vector<std::string>& args) { return test::runProgram(PROXGEN_BINARY_PATH, args); }

/// Runs proxgen, expects success, parses stdout as JSON.
json runJson(const std::vector<std::string>& args) {
  const ProcessResult r = runProxgen(args);
  EXPECT_EQ(r.code, 0) << r.err;
  try {
    return json::parse(r.out);
  } catch (const json::exception& e) {
    ADD_FAILURE() << "stdout is not JSON: " << e.what() << "\n" << r.out;
    return json();
  }
}

// --- inputs --------------------------------------------------------------------

/// A case's layout as a YAML file, so the binary reads what loadCaseSystem binds.
/// The shared cases use only name/link/type (checked), so nothing is lost.
std::string layoutYaml(const Layout& L) {
  std::string y = std::string("base: ") + (L.floatingBase ? "floating" : "fixed") + "\n";
  y += "constraints:\n";
  for (const Constraint& c : L.constraints) {
    EXPECT_TRUE(c.offset.p.isZero() && c.offset.R.isIdentity() && c.kp == 0 && c.kd == 0 && !c.hasTarget) << c.name;
    y += "  - {name: " + c.name + ", link: " + c.link + ", type: " + (c.type == ConstraintType::Weld6D ? "6d" : "3d") + "}\n";
  }
  return y;
}

json stateJson(const Model& m, const State& s) {
  return {{"q", configurationToJson(m, s.q)}, {"v", velocityToJson(m, s.v)}, {"tau", velocityToJson(m, s.tau)}};
}

// --- what the library says -----------------------------------------------------

struct Expected {
  VecX qdd, lambda;
  double residual = 0;
};

Expected libraryAnswer(const System& sys, const std::string& algorithm, const State& s, double mu, int K) {
  Data d(sys);
  Expected e;
  if (algorithm == "dense") {
    denseProx(assembleDense(sys, s.q, s.v, s.tau), mu, K, e.qdd, e.lambda);
  } else {
    if (algorithm == "caba") constrainedAba(sys, d, s.q, s.v, s.tau, mu, K);
    if (algorithm == "pv") proxPv(sys, d, s.q, s.v, s.tau, mu, K);
    if (algorithm == "ltl") proxLtl(sys, d, s.q, s.v, s.tau, mu, K);
    if (algorithm == "ltls") proxLtls(sys, d, s.q, s.v, s.tau, mu, K);
    e.qdd = d.qdd;
    e.lambda = d.lambda;
  }
  constraintJacobian(sys, d, s.q, s.v);
  e.residual = sys.nc == 0 ? 0.0 : (d.J * e.qdd + d.gamma - d.aStar).norm();
  return e;
}

/// One eval result against the library, slot by slot through the names.
void expectResult(const System& sys, const json& r, const Expected& e, const std::string& algorithm, double mu, int K) {
  const Model& m = sys.model;
  ASSERT_TRUE(r.is_object()) << r;
  EXPECT_EQ(r.at("algorithm"), algorithm);
  EXPECT_EQ(r.at("iterations").get<int>(), K);
  EXPECT_EQ(r.at("mu").get<double>(), mu);
  ASSERT_EQ(r.at("qdd").size(), std::size_t(m.numBodies() - 1));
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    const json& x = r.at("qdd").at(j.name);
    if (j.nv == 1) {
      EXPECT_EQ(x.get<double>(), e.qdd[j.idx_v]) << algorithm << " qdd " << j.name;
    } else {
      ASSERT_EQ(x.size(), std::size_t(j.nv)) << j.name;
      for (int k = 0; k < j.nv; ++k) EXPECT_EQ(x[k].get<double>(), e.qdd[j.idx_v + k]) << algorithm << " qdd " << j.name << "[" << k << "]";
    }
  }
  ASSERT_EQ(r.at("lambda").size(), sys.constraints.size());
  for (const Constraint& c : sys.constraints) {
    const json& x = r.at("lambda").at(c.name);
    ASSERT_EQ(x.size(), std::size_t(c.rows())) << c.name;
    for (int k = 0; k < c.rows(); ++k) EXPECT_EQ(x[k].get<double>(), e.lambda[c.row + k]) << algorithm << " lambda " << c.name << "[" << k << "]";
  }
  EXPECT_EQ(r.at("residual").get<double>(), e.residual) << algorithm;
}

const char* const kAlgorithms[] = {"caba", "pv", "ltl", "ltls", "dense"};

// --- check ---------------------------------------------------------------------

/// `check --json` against the System the library loads from the same files.
void expectLayoutJson(const System& sys, const json& j) {
  const Model& m = sys.model;
  EXPECT_EQ(j.at("nq").get<int>(), m.nq);
  EXPECT_EQ(j.at("nv").get<int>(), m.nv);
  EXPECT_EQ(j.at("nc").get<int>(), sys.nc);
  ASSERT_EQ(j.at("joints").size(), std::size_t(m.numBodies() - 1));
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& jt = m.bodies[i].joint;
    const json& x = j.at("joints")[i - 1];
    EXPECT_EQ(x.at("name"), jt.name) << "joint order differs at body " << i;
    EXPECT_EQ(x.at("type"), jointTypeName(jt.type));
    EXPECT_EQ(x.at("idx_q").get<int>(), jt.idx_q);
    EXPECT_EQ(x.at("nq").get<int>(), jt.nq);
    EXPECT_EQ(x.at("idx_v").get<int>(), jt.idx_v);
    EXPECT_EQ(x.at("nv").get<int>(), jt.nv);
    EXPECT_EQ(j.at("bodies")[i - 1].at("link"), m.bodies[i].link);
    EXPECT_EQ(j.at("bodies")[i - 1].at("parent").get<int>(), m.bodies[i].parent);
  }
  ASSERT_EQ(j.at("constraints").size(), sys.constraints.size());
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    const json& x = j.at("constraints")[k];
    EXPECT_EQ(x.at("name"), c.name);
    EXPECT_EQ(x.at("link"), c.link);
    EXPECT_EQ(x.at("row").get<int>(), c.row);
    EXPECT_EQ(x.at("rows").get<int>(), c.rows());
    EXPECT_EQ(x.at("body").get<int>(), c.body);
  }
  EXPECT_EQ(j.at("support").get<std::vector<int>>(), sys.supportBodies());
}

TEST(CliCheck, JsonOfTheSmallArm) {
  const System sys = loadSystem(good("arm3.urdf"), good("arm3_tool.yaml"));
  const ProcessResult r = runProxgen({"check", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  expectLayoutJson(sys, j);
  // The fixture: shoulder, elbow, slide in a chain; the tool link is merged into
  // the hand (body 3) by its fixed joint, and the point on it needs the whole chain.
  EXPECT_EQ(j.at("bodies")[2].at("merged_links"), json::array({"tool"}));
  EXPECT_EQ(j.at("joints")[1].at("urdf_type"), "continuous");
  EXPECT_EQ(j.at("joints")[1].at("mimic"), "shoulder");
  // The model's warning (the mimic joint) goes to stderr, never into the JSON.
  EXPECT_NE(r.err.find("proxgen: warning:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'elbow' mimics 'shoulder'"), std::string::npos) << r.err;
}

TEST(CliCheck, FloatingWithoutLayout) {
  const System sys = loadSystemWithoutLayout(good("arm3.urdf"), true);
  const json j = runJson({"check", good("arm3.urdf"), "--floating", "--json"});
  expectLayoutJson(sys, j);
  EXPECT_EQ(j.at("joints")[0].at("name"), "root_joint");
  EXPECT_EQ(j.at("joints")[0].at("nq").get<int>(), 7);
}

TEST(CliCheck, TextNamesEveryBodyAndConstraint) {
  const System sys = loadSystem(good("arm3.urdf"), good("arm3_tool.yaml"));
  const ProcessResult r = runProxgen({"check", good("arm3.urdf"), "--layout", good("arm3_tool.yaml")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("robot arm3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("nq 3, nv 3 (DoF), nc 3"), std::string::npos) << r.out;
  for (int i = 1; i < sys.model.numBodies(); ++i) {
    EXPECT_NE(r.out.find(sys.model.bodies[i].link), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(sys.model.bodies[i].joint.name), std::string::npos) << r.out;
  }
  EXPECT_NE(r.out.find("tool_point"), std::string::npos) << r.out;
}

TEST(CliCheck, JsonOfTheSharedCases) {
  PROXGEN_REQUIRE_MODELS();
  for (const char* name : {"iiwa_h6", "talos_f6x2_h6x2"}) {
    const Case c = loadCase(test::modelPath("cases.yaml"), name);
    const TempFile layout(".yaml");
    layout.write(layoutYaml(c.layout));
    const System sys = loadSystem(c.urdfPath, layout.path());
    const json j = runJson({"check", c.urdfPath, "--layout", layout.path(), "--json"});
    SCOPED_TRACE(name);
    expectLayoutJson(sys, j);
  }
}

// --- eval ----------------------------------------------------------------------

TEST(CliEval, SmallArmEveryAlgorithm) {
  const System sys = loadSystem(good("arm3.urdf"), good("arm3_tool.yaml"));
  const std::vector<State> states = loadStates(sys.model, good("arm3_state.json"));
  for (const char* algorithm : kAlgorithms) {
    const json r = runJson({"eval", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--state", good("arm3_state.json"),
                            "--algorithm", algorithm});
    expectResult(sys, r, libraryAnswer(sys, algorithm, states[0], sys.mu, sys.iterations), algorithm, sys.mu, sys.iterations);
  }
}

TEST(CliEval, SoloSameNumbersAsTheLibrary) {
  PROXGEN_REQUIRE_MODELS();
  const Case c = loadCase(test::modelPath("cases.yaml"), "solo_f3x2");
  const TempFile layout(".yaml"), one(".json"), list(".json");
  layout.write(layoutYaml(c.layout));
  const System sys = loadSystem(c.urdfPath, layout.path());
  std::mt19937 rng(20240607);
  json many = json::array();
  for (int k = 0; k < 3; ++k) many.push_back(stateJson(sys.model, randomState(sys.model, rng)));
  one.write(many[0].dump());
  list.write(many.dump());
  // Read back as the binary reads them: the inputs both sides solve from.
  const std::vector<State> oneState = loadStates(sys.model, one.path());
  const std::vector<State> states = loadStates(sys.model, list.path());

  for (const char* algorithm : kAlgorithms) {
    SCOPED_TRACE(algorithm);
    // One state object -> one result object, with the layout's defaults.
    const json r = runJson({"eval", c.urdfPath, "--layout", layout.path(), "--state", one.path(), "--algorithm", algorithm});
    expectResult(sys, r, libraryAnswer(sys, algorithm, oneState[0], sys.mu, sys.iterations), algorithm, sys.mu, sys.iterations);
    // A list -> a list, in order; K and mu from the command line.
    const double mu = 250.5;
    const int K = 7;
    const json rs = runJson({"eval", c.urdfPath, "--layout", layout.path(), "--state", list.path(), "--algorithm", algorithm,
                             "--iterations", std::to_string(K), "--mu", "250.5"});
    ASSERT_TRUE(rs.is_array()) << rs;
    ASSERT_EQ(rs.size(), states.size());
    for (std::size_t k = 0; k < states.size(); ++k)
      expectResult(sys, rs[k], libraryAnswer(sys, algorithm, states[k], mu, K), algorithm, mu, K);
  }
}

// A planar base (issue 13 item 3): root_joint's q is [x, y, cos, sin], here
// (3, 4) for the pair, which eval normalises to (0.6, 0.8) as the library's
// reader does; v and tau are 3-vectors, and qdd comes back as one.
TEST(CliEval, PlanarBaseEveryAlgorithm) {
  const System sys = loadSystem(good("arm3.urdf"), good("arm3_planar.yaml"));
  ASSERT_EQ(sys.model.bodies[1].joint.type, JointType::Planar);
  const std::vector<State> states = loadStates(sys.model, good("arm3_planar_state.json"));
  // (3, 4) / 4 over its norm: 0.6 and 0.8 to 2 ulp.
  EXPECT_NEAR(states[0].q[2], 0.6, 2e-16);
  EXPECT_NEAR(states[0].q[3], 0.8, 2e-16);
  for (const char* algorithm : kAlgorithms) {
    const json r = runJson({"eval", good("arm3.urdf"), "--layout", good("arm3_planar.yaml"), "--state",
                            good("arm3_planar_state.json"), "--algorithm", algorithm});
    expectResult(sys, r, libraryAnswer(sys, algorithm, states[0], sys.mu, sys.iterations), algorithm, sys.mu, sys.iterations);
    EXPECT_EQ(r.at("qdd").at("root_joint").size(), 3u) << algorithm;
  }
  const json j = runJson({"check", good("arm3.urdf"), "--layout", good("arm3_planar.yaml"), "--json"});
  expectLayoutJson(sys, j);
  EXPECT_EQ(j.at("base"), "planar");
  EXPECT_EQ(j.at("joints")[0].at("type"), "planar");
  // A zero (cos, sin) is one error line naming the file and the joint.
  const TempFile zero(".json");
  zero.write(R"({"q": {"root_joint": [0, 0, 0, 0], "shoulder": 0, "elbow": 0, "slide": 0},
                 "v": {"root_joint": [0, 0, 0], "shoulder": 0, "elbow": 0, "slide": 0}})");
  const ProcessResult bad = runProxgen({"eval", good("arm3.urdf"), "--layout", good("arm3_planar.yaml"), "--state", zero.path()});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find(zero.path() + ": q.'root_joint': the yaw direction [cos sin] is [0, 0]"), std::string::npos) << bad.err;
  EXPECT_TRUE(bad.out.empty()) << bad.out;
}

TEST(CliEval, FreeMotionAtZeroIterations) {
  // K = 0 is the unconstrained motion: multipliers exactly zero, and the
  // residual is what the free motion violates (the same J, gamma, aStar).
  const System sys = loadSystem(good("arm3.urdf"), good("arm3_tool.yaml"));
  const std::vector<State> states = loadStates(sys.model, good("arm3_state.json"));
  const json r = runJson({"eval", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--state", good("arm3_state.json"),
                          "--iterations", "0"});
  expectResult(sys, r, libraryAnswer(sys, "caba", states[0], sys.mu, 0), "caba", sys.mu, 0);
  for (const json& x : r.at("lambda").at("tool_point")) EXPECT_EQ(x.get<double>(), 0.0);
}

}  // namespace
}  // namespace proxgen

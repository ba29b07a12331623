// Hardening (docs/guarantees.md): what proxgen promises on hostile, huge and
// numerically extreme input, at the library level. Fixtures are in
// tests/data/hostile (hostile names, and every input a fuzz target in
// tests/fuzz found); the large robots are built here as strings.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

namespace fs = std::filesystem;
using test::kEps;

std::string hostile(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/hostile/" + file; }
std::string good(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + file; }

using test::errorOf;
using test::TempFile;

// An error message is one line of printable text, bounded whatever the input.
// The bound: quoted() shows at most 80 characters of a name, each at most as a
// 4-character \xNN escape, plus the "...' (N bytes)" note: < 360 per name; a
// message names at most two (a joint and its link), a third-party message is
// cut at 200 characters (oneLine, up to 4x when escaped), and the fixed texts
// are under 200 characters: 2 * 360 + 800 + 200 < 2000 beyond the file name.
constexpr std::size_t kMaxMessageBeyondPath = 2000;

void expectOneBoundedLine(const std::string& message, const std::string& path) {
  EXPECT_FALSE(message.empty());
  EXPECT_LE(message.size(), path.size() + kMaxMessageBeyondPath) << message.substr(0, 3000);
  for (unsigned char c : message) {
    if (c < 0x20 || c == 0x7f) {
      ADD_FAILURE() << "control character " << int(c) << " in: " << message.substr(0, 3000);
      break;
    }
  }
}

Constraint constraint(const std::string& name, const std::string& link, ConstraintType type) {
  Constraint c;
  c.name = name;
  c.link = link;
  c.type = type;
  return c;
}

System systemOf(Model model, std::vector<Constraint> constraints) {
  Layout layout;
  layout.floatingBase = model.floatingBase;
  layout.constraints = std::move(constraints);
  return bindLayout(std::move(model), layout);
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// ---------------------------------------------------------------------------
// Inputs the fuzz targets found (tests/fuzz); each input is in tests/data/hostile.

TEST(FuzzRegression, UrdfdomMessageWithControlCharacterIsEscaped) {
  // fuzz_urdf: urdfdom quotes a bad number raw ("lower value (-2\x1e.6) is not a valid float").
  const std::string path = hostile("urdfdom_control_char.urdf");
  const std::string m = errorOf([&] { loadUrdf(path, false); });
  expectOneBoundedLine(m, path);
  EXPECT_NE(m.find("\\x1e"), std::string::npos) << m;
}

TEST(FuzzRegression, YamlMessageWithControlCharacterIsEscaped) {
  // fuzz_layout: yaml-cpp's "unknown escape character: <byte>" printed the byte raw.
  const std::string path = hostile("yaml_escape_control_char.yaml");
  const std::string m = errorOf([&] { loadLayout(path); });
  expectOneBoundedLine(m, path);
  EXPECT_NE(m.find("malformed YAML"), std::string::npos) << m;
}

TEST(FuzzRegression, JsonMessageQuotingALongTokenIsCut) {
  // nlohmann-json quotes the last token read: a 1 MB unterminated string whole.
  TempFile f("long_token.json");
  const std::string path = f.write("{\"q\": \"" + std::string(1 << 20, 'x'));
  const Model m = loadUrdf(good("arm3.urdf"), false);
  const std::string msg = errorOf([&] { loadStates(m, path); });
  expectOneBoundedLine(msg, path);
  EXPECT_NE(msg.find("invalid JSON"), std::string::npos) << msg.substr(0, 500);
}

// ---------------------------------------------------------------------------
// Resource bounds.


// Solves a large system with ABA, constrainedABA and proxPV and checks each
// answer by its residual, which needs no dense reference of that size:
// RNEA(q, v, qdd) + J^T lambda = tau (docs/algorithms.md §6; lambda = 0 for ABA).
// Every solver here is a chain of backward-stable eliminations on M or on
// M + mu J^T J (tests/numerics.hpp), so the computed answer solves a problem
// perturbed by ~ n eps relative to the sizes of its terms, and the residual is
// bounded by kC n eps times those sizes, with no condition number:
// |M| |qdd| + |h| + |tau| + |J^T| |lambda| + mu |J^T| |J| |qdd| (the last term
// is the penalty of the primal algorithm; RNEA's own rounding is of the same
// kind). K = 0 must also be the free motion, bit for bit: the same sweeps as ABA.
struct Residual {
  double value, bound;
};

Residual dynamicsResidual(const System& sys, Data& d, const State& s, const VecX& qdd, const VecX& lambda) {
  const double n = double(sys.model.nv);
  const MatX M = crba(sys, d, s.q);
  const VecX h = nonLinearEffects(sys, d, s.q, s.v);
  constraintJacobian(sys, d, s.q, s.v);
  const MatX J = d.J;
  const VecX tau = rnea(sys, d, s.q, s.v, qdd) + J.transpose() * lambda;
  const double normM = M.cwiseAbs().rowwise().sum().maxCoeff();
  const double normJt = sys.nc ? J.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  const double normJ = sys.nc ? J.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
  const double q = qdd.cwiseAbs().maxCoeff();
  const double sizes = normM * q + h.cwiseAbs().maxCoeff() + s.tau.cwiseAbs().maxCoeff() +
                       normJt * (lambda.size() ? lambda.cwiseAbs().maxCoeff() : 0.0) + sys.mu * normJt * normJ * q;
  return {(tau - s.tau).cwiseAbs().maxCoeff(), test::kC * n * kEps * sizes};
}

void solveLarge(const System& sys, const char* label) {
  const Model& m = sys.model;
  std::mt19937 rng(7);
  const State s = test::randomState(m, rng);
  Data d(sys);
  const auto t0 = std::chrono::steady_clock::now();
  const VecX qdd = aba(sys, d, s.q, s.v, s.tau);
  const double tAba = seconds(t0);
  ASSERT_TRUE(qdd.allFinite()) << label;
  const Residual rAba = dynamicsResidual(sys, d, s, qdd, VecX::Zero(sys.nc));
  EXPECT_LE(rAba.value, rAba.bound) << label << ": ABA";

  constrainedAba(sys, d, s.q, s.v, s.tau, sys.mu, 0);
  EXPECT_EQ(d.qdd, qdd) << label << ": cABA at K = 0";
  EXPECT_TRUE(d.lambda.isZero(0.0)) << label;
  proxPv(sys, d, s.q, s.v, s.tau, sys.mu, 0);
  EXPECT_EQ(d.qdd, qdd) << label << ": proxPV at K = 0";

  const auto t1 = std::chrono::steady_clock::now();
  constrainedAba(sys, d, s.q, s.v, s.tau, sys.mu, 3);
  const double tCaba = seconds(t1);
  const VecX qddC = d.qdd, lambdaC = d.lambda;
  const auto t2 = std::chrono::steady_clock::now();
  proxPv(sys, d, s.q, s.v, s.tau, sys.mu, 3);
  const double tPv = seconds(t2);
  const VecX qddP = d.qdd, lambdaP = d.lambda;
  ASSERT_TRUE(qddC.allFinite() && lambdaC.allFinite() && qddP.allFinite() && lambdaP.allFinite()) << label;
  const Residual rC = dynamicsResidual(sys, d, s, qddC, lambdaC), rP = dynamicsResidual(sys, d, s, qddP, lambdaP);
  EXPECT_LE(rC.value, rC.bound) << label << ": cABA";
  EXPECT_LE(rP.value, rP.bound) << label << ": proxPV";
  std::printf("[ timing   ] %s: nv %d, ABA %.4f s, cABA(K=3) %.4f s, proxPV(K=3) %.4f s; residuals %.1e %.1e %.1e (bounds %.1e %.1e %.1e)\n",
              label, m.nv, tAba, tCaba, tPv, rAba.value, rC.value, rP.value, rAba.bound, rC.bound, rP.bound);
}

TEST(ResourceBounds, TwoThousandBodyTreeLoadsAndSolves) {
  const std::string xml = test::syntheticTreeUrdf(2000, 3);
  for (bool floating : {false, true}) {
    const auto t0 = std::chrono::steady_clock::now();
    Model m = parseUrdf(xml, "tree2000.urdf", floating);
    std::printf("[ timing   ] tree of 2000 bodies (%s): parse %.3f s\n", floating ? "floating" : "fixed", seconds(t0));
    ASSERT_EQ(m.numBodies(), 2000 + (floating ? 1 : 0));
    // Two welds and two point contacts on leaves of different branches.
    const System sys = systemOf(std::move(m), {constraint("w1", "l1999", ConstraintType::Weld6D),
                                               constraint("w2", "l1500", ConstraintType::Weld6D),
                                               constraint("p1", "l1000", ConstraintType::Point3D),
                                               constraint("p2", "l700", ConstraintType::Point3D)});
    solveLarge(sys, floating ? "tree 2000, floating" : "tree 2000, fixed");
  }
}

TEST(ResourceBounds, ChainAtTheDepthLimitLoadsAndSolves) {
  // kMaxTreeDepth joints from the root link to the tip: the deepest tree read.
  const std::string xml = test::syntheticTreeUrdf(int(kMaxTreeDepth) + 1, 1);
  const auto t0 = std::chrono::steady_clock::now();
  Model m = parseUrdf(xml, "chain.urdf", false);
  std::printf("[ timing   ] chain of %zu joints: parse %.3f s\n", kMaxTreeDepth, seconds(t0));
  ASSERT_EQ(m.nv, int(kMaxTreeDepth));
  const std::string tip = fmt::format("l{}", kMaxTreeDepth);
  solveLarge(systemOf(std::move(m), {constraint("tip", tip, ConstraintType::Point3D)}), "chain at the depth limit");
}

TEST(ResourceBounds, ChainDeeperThanTheLimitIsRefused) {
  // One joint more than kMaxTreeDepth: refused before the recursive build,
  // naming the first joint past the limit.
  const std::string xml = test::syntheticTreeUrdf(int(kMaxTreeDepth) + 2, 1);
  const std::string m = errorOf([&] { parseUrdf(xml, "deep.urdf", false); });
  expectOneBoundedLine(m, "deep.urdf");
  EXPECT_NE(m.find(fmt::format("joint 'j{}'", kMaxTreeDepth + 1)), std::string::npos) << m;
  EXPECT_NE(m.find(fmt::format("at most {} joints deep", kMaxTreeDepth)), std::string::npos) << m;
}

TEST(ResourceBounds, LinkCountIsBounded) {
  // kMaxUrdfLinks links load (parsed only: solving needs 24 nv^2 bytes, 0.4 GB
  // here); one more is refused right after the XML parse, at the extra element.
  const Model m = parseUrdf(test::syntheticTreeUrdf(int(kMaxUrdfLinks), 4), "max.urdf", true);
  EXPECT_EQ(m.nv, int(kMaxUrdfLinks) - 1 + 6);
  const std::string msg = errorOf([&] { parseUrdf(test::syntheticTreeUrdf(int(kMaxUrdfLinks) + 1, 4), "big.urdf", false); });
  expectOneBoundedLine(msg, "big.urdf");
  EXPECT_NE(msg.find(fmt::format("at most {} links", kMaxUrdfLinks)), std::string::npos) << msg;
  // A chain of that many links is refused by depth, in one linear pass (the
  // cycle walk it replaced was quadratic in the depth).
  const std::string deep = errorOf([&] { parseUrdf(test::syntheticTreeUrdf(int(kMaxUrdfLinks), 1), "deep.urdf", true); });
  EXPECT_NE(deep.find("joints deep"), std::string::npos) << deep;
}

TEST(ResourceBounds, MarkupIsBoundedBeforeAnyXmlParser) {
  // Tiny elements are what makes an XML DOM expensive (a 63 MB file of <a/>
  // took 3.7 GB): more than kMaxUrdfTags '<' are refused before parsing.
  std::string xml = "<robot name=\"r\">";
  xml.reserve(4 * kMaxUrdfTags + 32);
  for (std::size_t k = 0; k < kMaxUrdfTags; ++k) xml += "<a/>";
  xml += "</robot>";
  const std::string m = errorOf([&] { parseUrdf(xml, "tags.urdf", false); });
  expectOneBoundedLine(m, "tags.urdf");
  EXPECT_NE(m.find(fmt::format("has {} markup tags", kMaxUrdfTags + 2)), std::string::npos) << m;
}

TEST(ResourceBounds, ConstraintRowsAreBounded) {
  // kMaxConstraintRows rows load; the constraint that goes past them is refused,
  // with its line. 42 welds = 252 rows, plus one point contact = 255 rows, then
  // one more point contact makes 258.
  std::string yaml = "constraints:\n";
  for (int k = 0; k < kMaxConstraintRows / 6; ++k) yaml += fmt::format("  - {{name: w{}, link: tool, type: 6d}}\n", k);
  yaml += "  - {name: p0, link: tool, type: 3d}\n";
  const Layout ok = parseLayout(yaml, "rows.yaml");
  EXPECT_EQ(bindLayout(loadUrdf(good("arm3.urdf"), false), ok).nc, 255);
  yaml += "  - {name: p1, link: tool, type: 3d}\n";
  const std::string msg = errorOf([&] { parseLayout(yaml, "rows.yaml"); });
  expectOneBoundedLine(msg, "rows.yaml");
  EXPECT_NE(msg.find(fmt::format("rows.yaml:{}: constraints[{}]", kMaxConstraintRows / 6 + 3, kMaxConstraintRows / 6 + 1)),
            std::string::npos) << msg;
  EXPECT_NE(msg.find(fmt::format("at most {} rows", kMaxConstraintRows)), std::string::npos) << msg;
}

TEST(ResourceBounds, OversizedFilesAreRefusedBeforeReading) {
  TempFile urdf("big.urdf"), layout("big.yaml"), state("big.json");
  const std::string mu = errorOf([&] { loadUrdf(urdf.sized(kMaxUrdfBytes + 1), false); });
  expectOneBoundedLine(mu, urdf.path());
  EXPECT_NE(mu.find(fmt::format("more than the {} bytes", kMaxUrdfBytes)), std::string::npos) << mu;
  // The layout limit (4 MiB) is private to layout.cpp; 64 MiB is above it.
  const std::string ml = errorOf([&] { loadLayout(layout.sized(64u << 20)); });
  expectOneBoundedLine(ml, layout.path());
  EXPECT_NE(ml.find("bytes proxgen reads"), std::string::npos) << ml;
  // The state limit is 64 MiB (state.cpp).
  const Model arm = loadUrdf(good("arm3.urdf"), false);
  const std::string ms = errorOf([&] { loadStates(arm, state.sized((64u << 20) + 1)); });
  expectOneBoundedLine(ms, state.path());
  EXPECT_NE(ms.find(fmt::format("more than the {} bytes proxgen reads", kMaxStateBytes)), std::string::npos) << ms;
}

TEST(ResourceBounds, DeeplyNestedXmlIsAClearError) {
  // The scan before both XML parsers stops at 64 levels (kMaxXmlDepth), so
  // urdfdom's recursive TinyXML parser never sees them. 100000 levels with
  // their end tags are 1.5 MB.
  const std::size_t depth = 100000;
  std::string xml = "<robot name=\"r\"><link name=\"a\">";
  for (std::size_t k = 0; k < depth; ++k) xml += "<x>";
  for (std::size_t k = 0; k < depth; ++k) xml += "</x>";
  xml += "</link></robot>";
  const std::string m = errorOf([&] { parseUrdf(xml, "nested.urdf", false); });
  expectOneBoundedLine(m, "nested.urdf");
  EXPECT_NE(m.find(fmt::format("nested more than {} deep", kMaxXmlDepth)), std::string::npos) << m;
}

TEST(ResourceBounds, DeeplyNestedYamlIsAClearError) {
  // yaml-cpp 0.7 stops at 2000 levels (DeepRecursion) instead of overflowing the stack.
  const std::size_t depth = 100000;
  for (const std::string& text : {std::string(depth, '['), std::string(depth, '{'),
                                  std::string(depth, '[') + std::string(depth, ']')}) {
    const std::string m = errorOf([&] { parseLayout(text, "nested.yaml"); });
    expectOneBoundedLine(m, "nested.yaml");
    EXPECT_NE(m.find("nested.yaml"), std::string::npos) << m;
  }
  // Block style nests too: "- - - ... x".
  std::string block;
  for (std::size_t k = 0; k < depth; ++k) block += "- ";
  const std::string m = errorOf([&] { parseLayout(block + "x\n", "block.yaml"); });
  expectOneBoundedLine(m, "block.yaml");
}

TEST(ResourceBounds, DeeplyNestedJsonIsAClearError) {
  // nlohmann-json parses and destroys without recursion (3.10+), so depth costs
  // memory, not stack; the loader's parse callback stops at the fifth level,
  // deeper than any state, before the DOM holds it.
  const Model arm = loadUrdf(good("arm3.urdf"), false);
  TempFile open("open.json"), closed("closed.json"), inState("in_state.json");
  const std::size_t depth = 100000;
  const std::string m1 = errorOf([&] { loadStates(arm, open.write(std::string(depth, '['))); });
  expectOneBoundedLine(m1, open.path());
  EXPECT_NE(m1.find("nested more than 4 levels deep"), std::string::npos) << m1;
  const std::string m2 = errorOf([&] { loadStates(arm, closed.write(std::string(depth, '[') + std::string(depth, ']'))); });
  expectOneBoundedLine(m2, closed.path());
  EXPECT_NE(m2.find("nested more than 4 levels deep"), std::string::npos) << m2;
  const std::string deep = std::string(depth, '[') + std::string(depth, ']');
  const std::string m3 = errorOf([&] {
    loadStates(arm, inState.write("{\"q\": {\"shoulder\": " + deep + "}, \"v\": {}}"));
  });
  expectOneBoundedLine(m3, inState.path());
  EXPECT_NE(m3.find("after key 'shoulder': nested more than 4 levels deep"), std::string::npos) << m3;
}

// ---------------------------------------------------------------------------
// Numerical edge cases.

System arm3(bool floating, std::vector<Constraint> constraints) {
  return systemOf(loadUrdf(good("arm3.urdf"), floating), std::move(constraints));
}

nlohmann::json armState(bool floating) {
  nlohmann::json j = {{"q", {{"shoulder", 0.3}, {"elbow", -0.5}, {"slide", 0.05}}},
                      {"v", {{"shoulder", 0.1}, {"elbow", 0.2}, {"slide", -0.1}}},
                      {"tau", {{"shoulder", 1.0}}}};
  if (floating) {
    j["q"]["root_joint"] = {0.1, -0.2, 0.9, 0.1, 0.2, -0.3, 0.9};
    j["v"]["root_joint"] = {0.1, 0.0, -0.2, 0.3, 0.1, -0.1};
  }
  return j;
}

TEST(NumericalEdges, NonFiniteStateIsRejected) {
  // JSON text cannot hold NaN or Inf (tests/model/test_bad_input.cpp covers the
  // text); a json value built in code can, and stateFromJson must refuse it.
  const Model m = loadUrdf(good("arm3.urdf"), true);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (double bad : {nan, inf, -inf}) {
    for (const char* field : {"q", "v", "tau"}) {
      nlohmann::json j = armState(true);
      j[field]["elbow"] = bad;
      const std::string msg = errorOf([&] { stateFromJson(m, j, "state.json"); });
      EXPECT_NE(msg.find(fmt::format("{}.'elbow'", field)), std::string::npos) << msg;
      EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
    }
    nlohmann::json j = armState(true);
    j["q"]["root_joint"][4] = bad;  // inside the quaternion
    EXPECT_NE(errorOf([&] { stateFromJson(m, j, "state.json"); }).find("not finite"), std::string::npos);
  }
}

TEST(NumericalEdges, ZeroAndNegativeMuAreRejected) {
  for (const char* mu : {"0", "0.0", "-0", "-1", "-1e-300"}) {
    const std::string m = errorOf([&] { parseLayout(fmt::format("mu: {}\n", mu), "mu.yaml"); });
    EXPECT_NE(m.find("mu.yaml:1: mu: "), std::string::npos) << m;
    EXPECT_NE(m.find("> 0"), std::string::npos) << m;
  }
  // The solvers use 1/mu: the smallest positive double, whose reciprocal is
  // infinite, is refused; 1e-15 (1 / kMaxInputMagnitude) is the smallest accepted.
  EXPECT_NE(errorOf([] { parseLayout("mu: 4.9e-324\n", "mu.yaml"); }).find("mu.yaml:1: mu: "), std::string::npos);
  EXPECT_EQ(parseLayout("mu: 1e-15\n", "mu.yaml").mu, 1e-15);
}

TEST(NumericalEdges, ZeroIterationsIsTheFreeMotionForEveryAlgorithm) {
  // K = 0: no multiplier update, lambda = 0 exactly, qdd = M^-1 (tau - h).
  // cABA and proxPV run ABA's own sweeps then: bit-identical to aba(). proxLTL
  // and proxLTLs solve with the L^T D L factor of M from CRBA instead: equal to
  // round-off, kC n eps kappa_s(M) (tests/numerics.hpp).
  for (bool floating : {false, true}) {
    const System sys = arm3(floating, {constraint("tool", "tool", ConstraintType::Weld6D),
                                       constraint("hand", "hand", ConstraintType::Point3D)});
    const State s = stateFromJson(sys.model, armState(floating), "state");
    Data d(sys);
    const VecX free = aba(sys, d, s.q, s.v, s.tau);
    const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
    const double tol = test::kC * double(sys.model.nv) * kEps * test::scaledCondition(p.M);
    for (const test::Algorithm& a : test::kAlgorithms) {
      a.run(sys, d, s.q, s.v, s.tau, 1e4, 0);
      EXPECT_TRUE(d.lambda.isZero(0.0)) << a.name;
      EXPECT_EQ(d.lambda.size(), sys.nc) << a.name;
      if (a.run == constrainedAba || a.run == proxPv) EXPECT_EQ(d.qdd, free) << a.name;
      else EXPECT_LE(test::relErr(d.qdd, free), tol) << a.name;
    }
  }
}

TEST(NumericalEdges, UnnormalisedQuaternionIsNormalised) {
  const System sys = arm3(true, {constraint("tool", "tool", ConstraintType::Point3D)});
  nlohmann::json unit = armState(true), twice = armState(true);
  unit["q"]["root_joint"] = {0.1, -0.2, 0.9, 0, 0, 0, 1};
  twice["q"]["root_joint"] = {0.1, -0.2, 0.9, 0, 0, 0, 2};
  const State a = stateFromJson(sys.model, unit, "unit"), b = stateFromJson(sys.model, twice, "twice");
  EXPECT_EQ(a.q, b.q);  // 2 / |2| = 1 exactly
  Data d(sys);
  proxPv(sys, d, a.q, a.v, a.tau, sys.mu, 3);
  const VecX qddA = d.qdd;
  proxPv(sys, d, b.q, b.v, b.tau, sys.mu, 3);
  EXPECT_EQ(d.qdd, qddA);
  // A general quaternion scaled by 7.5: the normalised coefficients agree to a
  // few ulps (one division by a norm computed from differently rounded squares).
  nlohmann::json general = armState(true), scaled = armState(true);
  general["q"]["root_joint"] = {0, 0, 0, 0.3, -0.2, 0.5, 0.4};
  scaled["q"]["root_joint"] = {0, 0, 0, 0.3 * 7.5, -0.2 * 7.5, 0.5 * 7.5, 0.4 * 7.5};
  const VecX qg = stateFromJson(sys.model, general, "g").q, qs = stateFromJson(sys.model, scaled, "s").q;
  EXPECT_NEAR(qg.segment<4>(3).norm(), 1.0, 4 * kEps);
  EXPECT_LE((qg - qs).cwiseAbs().maxCoeff(), 4 * kEps);
}

TEST(NumericalEdges, JointLimitsAreNotEnforced) {
  // Positions outside <limit> are accepted and the dynamics are those of that
  // configuration: the loader does not clamp and the solvers do not either.
  const System sys = arm3(false, {});
  nlohmann::json j = armState(false);
  j["q"]["shoulder"] = 4.0;  // limit +-2.5
  j["q"]["slide"] = 0.5;     // limit [0, 0.1]
  const State s = stateFromJson(sys.model, j, "state");
  EXPECT_EQ(s.q[sys.model.bodies[sys.model.findJointBody("slide")].joint.idx_q], 0.5);
  Data d(sys);
  const VecX qdd = aba(sys, d, s.q, s.v, s.tau);
  // ABA's residual at the given (unclamped) q, bound as in solveLarge.
  const MatX M = crba(sys, d, s.q);
  const VecX h = nonLinearEffects(sys, d, s.q, s.v);
  const double bound = test::kC * 3 * kEps * (M.cwiseAbs().rowwise().sum().maxCoeff() * qdd.cwiseAbs().maxCoeff() + h.cwiseAbs().maxCoeff());
  EXPECT_LE((rnea(sys, d, s.q, s.v, qdd) - s.tau).cwiseAbs().maxCoeff(), bound);
  // ... and not those of the clamped one: the slide moves the hand 0.4 m along
  // the forearm, which changes the elbow's inertia by O(0.5 kg * 0.4^2 m^2).
  VecX clamped = s.q;
  clamped[sys.model.bodies[sys.model.findJointBody("slide")].joint.idx_q] = 0.1;
  clamped[sys.model.bodies[sys.model.findJointBody("shoulder")].joint.idx_q] = 2.5;
  EXPECT_GT(test::relErr(aba(sys, d, clamped, s.v, s.tau), qdd), 1e-3);
}

TEST(NumericalEdges, ConstraintOnTheWorldOfAFixedBaseIsInert) {
  // On a fixed base the root link (and links welded to it) belong to body 0,
  // the world. Such a constraint is accepted (a layout may be shared between
  // fixed and floating bases) and has no effect: its rows of J are zero, so
  // qdd is the motion without it, and its multipliers are those of the
  // residual it cannot reduce: each update adds mu (0 - a*), a* = -kp e
  // (Baumgarte, no velocity: the frame does not move), so lambda^K = K mu kp e
  // for every algorithm (docs/algorithms.md §3), and 0 without gains.
  const double mu = 100, kp = 10;
  Constraint world = constraint("world", "base_link", ConstraintType::Point3D);
  world.offset.p = Vec3(0, 0, 0.05);
  world.kp = kp;
  world.hasTarget = true;
  world.target.p = Vec3(0, 0, -0.05);  // e = R_C^T (p_C - p*) = (0, 0, 0.1)
  const Vec3 e(0, 0, 0.1);
  Constraint inert = constraint("inert", "base_link", ConstraintType::Weld6D);
  const System with = arm3(false, {constraint("tool", "tool", ConstraintType::Point3D), world, inert});
  const System without = arm3(false, {constraint("tool", "tool", ConstraintType::Point3D)});
  EXPECT_EQ(with.model.frames[with.model.findFrame("base_link")].body, 0);
  const State s = stateFromJson(with.model, armState(false), "state");
  Data dw(with), d0(without);
  const DenseProblem p = assembleDense(without, s.q, s.v, s.tau);
  const test::Bounds b = test::roundoffBounds(p, mu);
  for (const test::Algorithm& a : test::kAlgorithms) {
    for (int K : {1, 3}) {
      a.run(with, dw, s.q, s.v, s.tau, mu, K);
      a.run(without, d0, s.q, s.v, s.tau, mu, K);
      ASSERT_TRUE(dw.qdd.allFinite() && dw.lambda.allFinite()) << a.name;
      // Same algorithm with and without inert rows: round-off of one algorithm.
      const double tol = a.primal ? b.primal : b.dual;
      EXPECT_LE(test::relErr(dw.qdd, d0.qdd), tol) << a.name << " K=" << K;
      EXPECT_LE(test::relErr(dw.lambda.head<3>(), d0.lambda), tol) << a.name << " K=" << K;
      // lambda^K = K mu kp e. Each update's residual is a difference of terms
      // of size |g| (the gravity in k_i against the world's a_0 = -a_g) and
      // kp |e| (the target), rounded a few times and scaled by mu; K updates
      // add up: error <= 10 K mu eps (|g| + kp |e|) (7e-12 here, against 300).
      const double tolLambda = 10 * K * mu * kEps * (with.model.gravity.norm() + kp * e.norm());
      const VecX lw = dw.lambda.segment<3>(3), expected = K * mu * kp * e;
      EXPECT_LE((lw - expected).cwiseAbs().maxCoeff(), tolLambda) << a.name << " K=" << K;
      EXPECT_LE(dw.lambda.tail<6>().cwiseAbs().maxCoeff(), tolLambda) << a.name << " K=" << K;
    }
  }
}

// ---------------------------------------------------------------------------
// Hostile names (tests/data/hostile/README.md): the loaders keep them byte for
// byte, and every message that quotes one stays one bounded line.

TEST(HostileNames, UrdfKeepsEveryNameExactly) {
  for (bool floating : {false, true}) {
    const Model m = loadUrdf(hostile("names.urdf"), floating);
    EXPECT_EQ(m.name, "hostile \"robot\" */ ?\?/");
    EXPECT_EQ(m.nv, 10 + (floating ? 6 : 0));
    for (const char* joint : {"j'1\\", "line1\n#include <cstdlib>\n", "class", "namespace", "j-x", "j.x", "j_x",
                              "%s %n {} {0} {:x}", "__reserved", "NAN"})
      EXPECT_GT(m.findJointBody(joint), 0) << joint;
    for (const char* link : {"base \"link\"", "*/ int main() { return 1; } /*", "?\?/ ?\?= ?\?( ?\?) trigraphs", "int",
                             "1st_link", "\xc5\x82\xc4\x85\x63ze_\xe6\x97\xa5\xe6\x9c\xac_\xf0\x9f\xa4\x96", "a-b",
                             "a.b", "a b", "a_b", "tab\tcr\rend\\", "_Upper", "assert", "main"})
      EXPECT_GE(m.findFrame(link), 0) << link;
    // Four names that sanitise alike are four frames.
    EXPECT_EQ(m.findFrame("a b") == m.findFrame("a_b"), false);
  }
}

TEST(HostileNames, LayoutAndStateLoadAndSolve) {
  const System sys = loadSystem(hostile("names.urdf"), hostile("names.yaml"));
  ASSERT_EQ(sys.constraints.size(), 5u);
  EXPECT_EQ(sys.constraints[0].name, "weld */ \"q\" \\ ?\?/");
  EXPECT_EQ(sys.constraints[1].name, "line1\n#include <cstdlib>\n");
  EXPECT_EQ(sys.nc, 6 + 4 * 3);
  const std::vector<State> states = loadStates(sys.model, hostile("names_state.json"));
  ASSERT_EQ(states.size(), 1u);
  const State& s = states[0];
  EXPECT_EQ(s.q[sys.model.bodies[sys.model.findJointBody("class")].joint.idx_q], 0.05);
  Data d(sys);
  constrainedAba(sys, d, s.q, s.v, s.tau, sys.mu, 3);
  const VecX qdd = d.qdd;
  proxPv(sys, d, s.q, s.v, s.tau, sys.mu, 3);
  const test::Bounds b = test::roundoffBounds(assembleDense(sys, s.q, s.v, s.tau), sys.mu);
  EXPECT_LE(test::relErr(qdd, d.qdd), b.primal + b.dual);
  const System fixed = loadSystem(hostile("names.urdf"), hostile("names_fixed.yaml"));
  EXPECT_EQ(fixed.constraints[0].name, "%s %n {} {0} \t\r end\\");
}

TEST(HostileNames, TenKilobyteNamesLoad) {
  const System sys = loadSystem(hostile("long_names.urdf"), hostile("long_names.yaml"));
  ASSERT_EQ(sys.constraints.size(), 1u);
  EXPECT_GE(sys.constraints[0].name.size(), 10000u);
  EXPECT_GE(sys.model.bodies[1].joint.name.size(), 10000u);
  EXPECT_GE(sys.model.bodies[1].link.size(), 10000u);
  EXPECT_EQ(sys.constraints[0].body, 1);
}

/// A URDF with the <axis> of the joint whose element starts with `jointStart`
/// set to zero length (a load error naming the joint).
std::string withZeroAxis(const std::string& xml, const std::string& jointStart) {
  const std::size_t at = xml.find(jointStart);
  EXPECT_NE(at, std::string::npos) << jointStart;
  const std::size_t axis = xml.find("<axis xyz=\"", at);
  std::string out = xml;
  out.replace(axis, xml.find("\"/>", axis) + 3 - axis, "<axis xyz=\"0 0 0\"/>");
  return out;
}

TEST(HostileNames, MessagesQuotingThemStayOneBoundedLine) {
  const std::string names = test::slurp(hostile("names.urdf"));
  const std::string longNames = test::slurp(hostile("long_names.urdf"));
  // URDF errors naming a joint with newlines, one with a trailing backslash, one of 10 kB.
  std::string m = errorOf([&] { parseUrdf(withZeroAxis(names, "<joint name=\"line1&#10;#include &lt;cstdlib&gt;&#10;\""), "n.urdf", false); });
  expectOneBoundedLine(m, "n.urdf");
  EXPECT_NE(m.find("joint 'line1\\x0a#include <cstdlib>\\x0a'"), std::string::npos) << m;
  m = errorOf([&] { parseUrdf(withZeroAxis(names, "<joint name=\"j'1\\\""), "n.urdf", false); });
  expectOneBoundedLine(m, "n.urdf");
  EXPECT_NE(m.find("joint 'j\\'1\\\\'"), std::string::npos) << m;
  // (make_long_names.py quotes attributes holding '"' with single quotes)
  m = errorOf([&] { parseUrdf(withZeroAxis(longNames, "<joint name='joint_"), "l.urdf", false); });
  expectOneBoundedLine(m, "l.urdf");
  EXPECT_NE(m.find("bytes)"), std::string::npos) << m;

  // A layout naming an unknown link of 10 kB with newlines, under a hostile constraint name.
  const Model model = loadUrdf(hostile("names.urdf"), false);
  const std::string linkName = std::string(5000, 'x') + "\n#include <x>\n" + std::string(5000, '*');
  Layout layout;
  layout.sourcePath = "layout.yaml";
  layout.constraints.push_back(constraint("c */\n", linkName, ConstraintType::Point3D));
  m = errorOf([&] { bindLayout(model, layout); });
  expectOneBoundedLine(m, "layout.yaml");

  // A state keyed by an unknown 10 kB joint name, and one missing a hostile joint.
  nlohmann::json j = nlohmann::json::parse(test::slurp(hostile("names_state.json")));
  j["q"].erase("root_joint");  // the model here has a fixed base
  j["v"].erase("root_joint");
  EXPECT_NO_THROW(stateFromJson(model, j, "state.json"));
  nlohmann::json unknown = j;
  unknown["v"][linkName] = 1.0;
  m = errorOf([&] { stateFromJson(model, unknown, "state.json"); });
  expectOneBoundedLine(m, "state.json");
  EXPECT_NE(m.find("v.'" + std::string(80, 'x') + "...' (10014 bytes): is not a joint"), std::string::npos) << m;
  nlohmann::json missing = j;
  missing["q"].erase("line1\n#include <cstdlib>\n");
  m = errorOf([&] { stateFromJson(model, missing, "state.json"); });
  expectOneBoundedLine(m, "state.json");
  EXPECT_NE(m.find("q.'line1\\x0a#include <cstdlib>\\x0a': missing"), std::string::npos) << m;

  // The fixture's own load errors through the layout reader: a duplicate hostile name.
  const std::string dup = "constraints:\n  - {name: \"a\\nb\", link: int, type: 3d}\n  - {name: \"a\\nb\", link: int, type: 3d}\n";
  m = errorOf([&] { parseLayout(dup, "dup.yaml"); });
  expectOneBoundedLine(m, "dup.yaml");
  EXPECT_NE(m.find("'a\\x0ab'"), std::string::npos) << m;
}

}  // namespace
}  // namespace proxgen

// Mobile bases in the model (issue 13 item 3): `base: planar` in the layout,
// URDF `planar` and `floating` joints, their slots, placements and neutral
// configuration, the states that hold them, and the errors decided in
// docs/design.md, "Conventions".
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "model/layout.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::errorOf;

std::string good(const std::string& f) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + f; }
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const char* const kInertial =
    "<inertial><mass value='1'/><inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial>";
std::string link(const std::string& name) { return fmt::format("<link name='{}'>{}</link>", name, kInertial); }
std::string joint(const std::string& name, const std::string& type, const std::string& parent, const std::string& child,
                  const std::string& extra = "") {
  return fmt::format("<joint name='{}' type='{}'><parent link='{}'/><child link='{}'/>{}</joint>", name, type, parent,
                     child, extra);
}
std::string robot(const std::string& body) { return "<robot name='r'>" + body + "</robot>"; }
const char* const kLimit = "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/>";

TEST(MobileBaseLayout, BasePlanarIsRead) {
  const Layout L = parseLayout("base: planar\n", "p.yaml");
  EXPECT_TRUE(L.planarBase);
  EXPECT_FALSE(L.floatingBase);
  EXPECT_EQ(L.base(), BaseType::Planar);
  EXPECT_EQ(parseLayout("base: floating\n", "f.yaml").base(), BaseType::Floating);
  EXPECT_EQ(parseLayout("base: fixed\n", "x.yaml").base(), BaseType::Fixed);
  const std::string m = errorOf([] { parseLayout("base: wheeled\n", "w.yaml"); });
  EXPECT_TRUE(has(m, "w.yaml:1: base: 'wheeled' is none of 'fixed', 'floating', 'planar'")) << m;
}

// `base: planar` puts the root link on a planar joint `root_joint` in the
// world's x-y plane: nq 4, nv 3, first in q and v, the other joints after it.
TEST(MobileBaseModel, BasePlanarAddsAPlanarRootJoint) {
  const Model fixed = loadUrdf(good("arm3.urdf"), BaseType::Fixed);
  const Model m = loadUrdf(good("arm3.urdf"), BaseType::Planar);
  EXPECT_TRUE(m.planarBase);
  EXPECT_FALSE(m.floatingBase);
  ASSERT_EQ(m.numBodies(), fixed.numBodies() + 1);
  const Joint& root = m.bodies[1].joint;
  EXPECT_EQ(root.name, "root_joint");
  EXPECT_EQ(root.type, JointType::Planar);
  EXPECT_EQ(std::string(jointTypeName(root.type)), "planar");
  EXPECT_EQ(root.nq, 4);
  EXPECT_EQ(root.nv, 3);
  EXPECT_EQ(m.nq, fixed.nq + 4);
  EXPECT_EQ(m.nv, fixed.nv + 3);
  EXPECT_EQ(m.bodies[2].joint.idx_q, 4);
  EXPECT_EQ(m.bodies[2].joint.idx_v, 3);
  EXPECT_EQ(m.bodies[1].parent, 0);
  // Neutral: at the origin, yaw 0, i.e. (cos, sin) = (1, 0).
  VecX neutral = VecX::Zero(m.nq);
  neutral[2] = 1.0;
  EXPECT_EQ(m.neutral(), neutral);
  // S: linear x, linear y, angular z, constant in the body frame.
  Mat6X S = Mat6X::Zero(6, 3);
  S(0, 0) = S(1, 1) = S(5, 2) = 1.0;
  EXPECT_EQ(m.motionSubspace(1), S);
}

// The placement of a planar joint: X_T * (Rz(yaw), [x, y, 0]), with (cos, sin)
// read from q as given. planar_mobile.urdf's base joint has X_T = (rpy 0 0 0.3,
// xyz 0.1 -0.2 0.05); its puck joint sits below the moving pole.
TEST(MobileBaseModel, UrdfPlanarJointsAnywhereInTheTree) {
  const Model m = loadUrdf(good("planar_mobile.urdf"), BaseType::Fixed);
  ASSERT_EQ(m.numBodies(), 4);  // world, cart, pole, puck (puck_tip is merged)
  EXPECT_EQ(m.bodies[1].joint.name, "base_planar");
  EXPECT_EQ(m.bodies[1].joint.type, JointType::Planar);
  EXPECT_EQ(m.bodies[1].joint.urdfType, "planar");
  EXPECT_EQ(m.bodies[3].joint.name, "puck_planar");
  EXPECT_EQ(m.bodies[3].joint.type, JointType::Planar);
  EXPECT_EQ(m.bodies[3].parent, 2);
  EXPECT_EQ(m.nq, 4 + 1 + 4);
  EXPECT_EQ(m.nv, 3 + 1 + 3);
  EXPECT_EQ(m.bodies[3].joint.idx_q, 5);
  EXPECT_EQ(m.bodies[3].joint.idx_v, 4);
  EXPECT_FALSE(m.planarBase);  // the layout's base is fixed; the file's joint is a joint

  const double yaw = 0.7, x = 0.4, y = -1.1;
  VecX q = m.neutral();
  q.segment<4>(0) << x, y, std::cos(yaw), std::sin(yaw);
  const SE3 XT{rpyToMatrix(Vec3(0, 0, 0.3)), Vec3(0.1, -0.2, 0.05)};
  const SE3 expected = XT * SE3{Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix(), Vec3(x, y, 0)};
  const SE3 got = m.jointPlacement(1, q);
  // urdfdom turns the rpy into a quaternion and back; rpyToMatrix does not:
  // a few eps on entries of size at most 1.5, so 1e-14 (45 eps) is ample, and
  // a wrong sign or order of the planar rotation is off by 0.1 or more.
  EXPECT_LE((got.R - expected.R).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LE((got.p - expected.p).cwiseAbs().maxCoeff(), 1e-14);
}

// A URDF floating joint on a link fixed to the world is a free flyer under its
// own name, with its <origin> as the tree placement.
TEST(MobileBaseModel, UrdfFloatingJointOnTheWorldIsAFreeFlyer) {
  const Model m = loadUrdf(good("floating_joint.urdf"), BaseType::Fixed);
  ASSERT_EQ(m.numBodies(), 3);
  const Joint& j = m.bodies[1].joint;
  EXPECT_EQ(j.name, "hull_float");
  EXPECT_EQ(j.type, JointType::FreeFlyer);
  EXPECT_EQ(j.nq, 7);
  EXPECT_EQ(j.nv, 6);
  EXPECT_EQ(m.bodies[1].parent, 0);
  EXPECT_EQ(m.bodies[1].treePlacement.p, Vec3(0.3, 0, 0.2));
  EXPECT_EQ(m.nq, 8);
  EXPECT_EQ(m.neutral()[6], 1.0);  // qw
}

TEST(MobileBaseErrors, FloatingJointBelowAMovingBody) {
  const std::string xml = robot(link("a") + link("b") + link("c") + joint("ab", "revolute", "a", "b", kLimit) +
                                joint("free", "floating", "b", "c"));
  const std::string m = errorOf([&] { parseUrdf(xml, "t.urdf", BaseType::Fixed); });
  EXPECT_TRUE(has(m, "t.urdf:1: joint 'free': floating joint below link 'b', which moves")) << m;
}

// With `base: floating` the root link already floats: a floating joint on it
// would be a second free flyer on top of the first.
TEST(MobileBaseErrors, FloatingJointWithBaseFloating) {
  const std::string xml = robot(link("world") + link("hull") + joint("float", "floating", "world", "hull"));
  EXPECT_NO_THROW(parseUrdf(xml, "t.urdf", BaseType::Fixed));
  const std::string m = errorOf([&] { parseUrdf(xml, "t.urdf", BaseType::Floating); });
  EXPECT_TRUE(has(m, "t.urdf:1: joint 'float': floating joint on link 'world', which `base: floating` already makes a "
                     "free flyer"))
      << m;
  // With `base: planar` the root link moves too: the joint is below a moving body.
  EXPECT_TRUE(has(errorOf([&] { parseUrdf(xml, "t.urdf", BaseType::Planar); }), "below link 'world', which moves"));
}

TEST(MobileBaseErrors, PlanarJointAxisMustBePlusZ) {
  for (const char* axis : {"0 0 -1", "1 0 0", "0 1 0", "0 0.6 0.8"}) {
    const std::string xml = robot(link("a") + link("b") + joint("p", "planar", "a", "b", fmt::format("<axis xyz='{}'/>", axis)));
    const std::string m = errorOf([&] { parseUrdf(xml, "t.urdf", BaseType::Fixed); });
    EXPECT_TRUE(has(m, "t.urdf:1: joint 'p': planar joint with <axis> [")) << axis << ": " << m;
    EXPECT_TRUE(has(m, "rotate the joint's <origin>")) << m;
  }
  // No <axis>: urdfdom's default [1, 0, 0], named as such.
  const std::string m = errorOf([] { parseUrdf(robot(link("a") + link("b") + joint("p", "planar", "a", "b")), "t.urdf", BaseType::Fixed); });
  EXPECT_TRUE(has(m, "<axis> [1, 0, 0] (urdfdom reads a missing <axis> as [1, 0, 0])")) << m;
  // +z, of any length, is the joint frame's x-y plane.
  for (const char* axis : {"0 0 1", "0 0 2.5"}) {
    const Model ok = parseUrdf(robot(link("a") + link("b") + joint("p", "planar", "a", "b", fmt::format("<axis xyz='{}'/>", axis))),
                               "t.urdf", BaseType::Fixed);
    EXPECT_EQ(ok.bodies[1].joint.type, JointType::Planar) << axis;
  }
}

// A planar joint's q in JSON: [x, y, cos, sin], the pair normalised like the
// quaternion (by its largest component first), [0, 0] and non-finite refused.
TEST(MobileBaseState, PlanarConfigurationIsReadAndNormalised) {
  const Model m = loadUrdf(good("arm3.urdf"), BaseType::Planar);
  auto state = [](const nlohmann::json& root) {
    return nlohmann::json{{"q", {{"root_joint", root}, {"shoulder", 0.3}, {"elbow", -0.5}, {"slide", 0.05}}},
                          {"v", {{"root_joint", {0.1, 0.2, 0.3}}, {"shoulder", 0}, {"elbow", 0}, {"slide", 0}}}};
  };
  const State s = stateFromJson(m, state({1.0, 2.0, 3.0, 4.0}), "s.json");
  EXPECT_EQ(s.q[0], 1.0);
  EXPECT_EQ(s.q[1], 2.0);
  // (3, 4) / 4 = (0.75, 1), over its norm 1.25: 0.6 and 0.8 to rounding (2 ulp).
  EXPECT_NEAR(s.q[2], 0.6, 2e-16);
  EXPECT_NEAR(s.q[3], 0.8, 2e-16);
  EXPECT_EQ(s.v.head<3>(), Vec3(0.1, 0.2, 0.3));
  // Huge and tiny pairs: scaled first, so neither overflows nor underflows.
  for (double x : {1e300, 1e-300}) {
    const State big = stateFromJson(m, state({0, 0, -x, x}), "s.json");
    EXPECT_NEAR(big.q[2], -std::sqrt(0.5), 2e-16);
    EXPECT_NEAR(big.q[3], std::sqrt(0.5), 2e-16);
  }
  std::string e = errorOf([&] { stateFromJson(m, state({1, 2, 0, 0}), "s.json"); });
  EXPECT_TRUE(has(e, "s.json: q.'root_joint': the yaw direction [cos sin] is [0, 0]")) << e;
  e = errorOf([&] { stateFromJson(m, state({1, 2, std::nan(""), 1}), "s.json"); });
  EXPECT_TRUE(has(e, "q.'root_joint'[2]: is not finite")) << e;
  e = errorOf([&] { stateFromJson(m, state({1, 2, 1}), "s.json"); });
  EXPECT_TRUE(has(e, "q.'root_joint': expected a list of 4 numbers")) << e;
  e = errorOf([&] { stateFromJson(m, state({1, 2, 1, "x"}), "s.json"); });
  EXPECT_TRUE(has(e, "q.'root_joint'[3]: expected a number")) << e;
  // v of a planar joint: three numbers.
  nlohmann::json j = state({0, 0, 1, 0});
  j["v"]["root_joint"] = {1, 2};
  EXPECT_TRUE(has(errorOf([&] { stateFromJson(m, j, "s.json"); }), "v.'root_joint': expected a list of 3 numbers"));
}

// Random states (tests, `verify`) hold a unit (cos, sin).
TEST(MobileBaseState, RandomPlanarStatesAreValid) {
  const Model m = loadUrdf(good("planar_mobile.urdf"), BaseType::Fixed);
  std::mt19937 rng(5);
  for (int k = 0; k < 20; ++k) {
    const State s = randomState(m, rng);
    for (int i : {1, 3}) {
      const int at = m.bodies[i].joint.idx_q;
      // cos^2 + sin^2 of a computed angle: within a few eps of 1.
      EXPECT_NEAR(std::hypot(s.q[at + 2], s.q[at + 3]), 1.0, 4e-16);
    }
  }
}

}  // namespace
}  // namespace proxgen

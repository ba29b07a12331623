// Every bad input gets one proxgen::Error whose one-line message names the file
// (with the line where the loader knows it), the element and what is wrong
// (docs/design.md, "Bad input"). The fixtures are small files under
// tests/data/bad; the layouts and states there are read against
// tests/data/good/arm3.urdf. The last suite runs the `proxgen` binary: exit code
// non-zero, the message on stderr, nothing on stdout.
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::errorOf;
using test::ProcessResult;

std::string bad(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/bad/" + file; }
std::string good(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + file; }

/// "PATH:LINE" where LINE is the 1-based line of `path` holding `needle`, so the
/// expected line numbers follow the fixtures instead of being typed in.
std::string at(const std::string& path, const std::string& needle) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.find(needle) != std::string::npos) return path + ":" + std::to_string(n);
  ADD_FAILURE() << needle << " not in " << path;
  return path;
}

/// The message is one line and holds every part (file, element, what).
void expectMessage(const std::string& message, std::initializer_list<std::string> parts) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

Model urdf(const std::string& file) { return loadUrdf(bad(file), false); }
System withLayout(const std::string& file) { return loadSystem(good("arm3.urdf"), bad(file)); }
std::vector<State> states(const std::string& layout, const std::string& file) {
  return loadStates(loadSystem(good("arm3.urdf"), good(layout)).model, bad(file));
}

// --- URDF --------------------------------------------------------------------

TEST(BadUrdf, MissingFile) {
  expectMessage(errorOf([] { urdf("does_not_exist.urdf"); }), {bad("does_not_exist.urdf") + ": ", "cannot open the URDF file: No such file or directory"});
}

TEST(BadUrdf, DirectoryInsteadOfFile) {
  const std::string dir = std::string(PROXGEN_TEST_DATA_DIR) + "/bad";
  expectMessage(errorOf([&] { loadUrdf(dir, false); }), {dir + ": ", "cannot read the URDF file: Is a directory"});
}

TEST(BadUrdf, NotXml) {
  expectMessage(errorOf([] { urdf("not_xml.urdf"); }), {bad("not_xml.urdf") + ":1", "not well-formed XML"});
}

// Issue 18 item 8: a xacro file is well-formed XML, and urdfdom's own message on
// it (a number that is not a double, a missing link) hid the cause. Refused at
// the first xacro markup (here <xacro:property>; the namespace on <robot> alone
// is not markup) with the command to run; robot.urdf.xacro expands to robot.urdf.
TEST(BadUrdf, XacroFileIsToldToRunXacro) {
  const std::string f = bad("xacro_macro.urdf.xacro");
  expectMessage(errorOf([&] { loadUrdf(f, false); }),
                {at(f, "<xacro:property") + ": element <xacro:property>: a xacro element: this is a xacro file, not a URDF: "
                                            "run xacro first (xacro " + f + " > " + bad("xacro_macro.urdf") + ")"});
}

// No namespace, no xacro element: one ${...} left in an attribute is found (its
// line and attribute named), and the suggested output never overwrites the input.
TEST(BadUrdf, LeftoverXacroExpression) {
  const std::string f = bad("xacro_expression.urdf");
  expectMessage(errorOf([&] { loadUrdf(f, false); }),
                {at(f, "${pi/2}") + ": ", "element <origin> attribute 'rpy'", "'0 0 ${pi/2}' is a xacro expression",
                 "(xacro " + f + " > " + bad("xacro_expression.expanded.urdf") + ")"});
}

// Each kind of xacro markup on its own, and what must pass: a comment that
// mentions xacro (the banner xacro writes into every file it expands), and the
// xmlns:xacro declaration that xacro before 1.13.3 left on the <robot> of every
// file it expanded (ros/xacro#144).
TEST(BadUrdf, EveryKindOfXacroMarkupAndNothingElse) {
  const std::string link = R"(<link name="a"><inertial><mass value="1"/>)"
                           R"(<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>)";
  const auto robot = [&](const std::string& inside) { return "<robot name=\"r\">\n" + inside + "\n" + link + "\n</robot>\n"; };
  struct Case {
    std::string inside, expected;
  };
  for (const Case& c : {Case{R"(<xacro:include filename="arm.xacro"/>)", "t.robot:2: element <xacro:include>: a xacro element"},
                        Case{R"x(<material name="m"><color rgba="$(arg color)"/></material>)x",
                             "t.robot:2: element <color> attribute 'rgba': '$(arg color)' is a xacro expression"},
                        Case{R"(<material name="m">${colour}</material>)", "t.robot:2: element <material>: a xacro expression"}}) {
    const std::string m = errorOf([&] { parseUrdf(robot(c.inside), "t.robot", false); });
    expectMessage(m, {c.expected, "run xacro first (xacro t.robot > t.robot.urdf)"});
  }
  const Model ok = parseUrdf(robot("<!-- generated by xacro from ${robot}.urdf.xacro: $(find pkg) -->"), "t.urdf", false);
  EXPECT_EQ(ok.frames.size(), 1u);
  const Model expanded = parseUrdf(R"(<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">)" + link + "</robot>",
                                   "old_xacro_output.urdf", false);
  EXPECT_EQ(expanded.frames.size(), 1u);
}

TEST(BadUrdf, XmlThatIsNotUrdf) {
  expectMessage(errorOf([] { urdf("not_urdf.urdf"); }), {bad("not_urdf.urdf"), "<robot>", "not a URDF"});
}

TEST(BadUrdf, Cycle) {
  // Which of the three joints is named depends on where the walk starts; all close the cycle.
  const std::string m = errorOf([] { urdf("cycle.urdf"); });
  expectMessage(m, {bad("cycle.urdf") + ":", "joint '", "cycle"});
  const bool namesOne = m.find("joint 'ab'") != std::string::npos || m.find("joint 'bc'") != std::string::npos ||
                        m.find("joint 'ca'") != std::string::npos;
  EXPECT_TRUE(namesOne) << m;
}

TEST(BadUrdf, TwoRoots) {
  expectMessage(errorOf([] { urdf("two_roots.urdf"); }), {bad("two_roots.urdf"), "[a]", "[c]", "root"});
}

TEST(BadUrdf, UnknownJointType) {
  expectMessage(errorOf([] { urdf("unknown_joint_type.urdf"); }), {bad("unknown_joint_type.urdf"), "spin_joint", "helical"});
}

// A planar joint moves in its joint frame's x-y plane: an <axis> (the plane's
// normal) other than +z is refused, naming the axis (docs/design.md, "Conventions").
TEST(BadUrdf, PlanarJointOutsideItsFramesXyPlane) {
  const std::string f = bad("planar_joint.urdf");
  expectMessage(errorOf([] { urdf("planar_joint.urdf"); }),
                {at(f, "\"table_joint\""), "joint 'table_joint'", "planar joint with <axis> [0, 1, 0]", "<axis xyz=\"0 0 1\">"});
}

TEST(BadUrdf, FloatingJointInsideTheTree) {
  const std::string f = bad("floating_inside.urdf");
  expectMessage(errorOf([] { urdf("floating_inside.urdf"); }), {at(f, "\"free_joint\""), "joint 'free_joint'", "root"});
}

TEST(BadUrdf, MovingChainWithZeroMass) {
  const std::string f = bad("zero_mass_chain.urdf");
  expectMessage(errorOf([] { urdf("zero_mass_chain.urdf"); }),
                {at(f, "joint name=\"lift\""), "joint 'lift'", "'massless_arm'", "no mass"});
}

TEST(BadUrdf, NanMass) {
  // urdfdom rejects the number (and would otherwise leave a 0 in its place).
  expectMessage(errorOf([] { urdf("nan_mass.urdf"); }), {bad("nan_mass.urdf"), "[nan_link]", "mass [nan]"});
}

TEST(BadUrdf, OverflowingInertia) {
  expectMessage(errorOf([] { urdf("inf_inertia.urdf"); }), {bad("inf_inertia.urdf"), "[huge_link]", "ixx"});
}

TEST(BadUrdf, NegativeMass) {
  const std::string f = bad("negative_mass.urdf");
  expectMessage(errorOf([] { urdf("negative_mass.urdf"); }), {at(f, "\"heavy_link\""), "link 'heavy_link'", "negative mass"});
}

TEST(BadUrdf, InertiaNotPositiveSemidefinite) {
  // ixx = iyy = 1, ixy = 5: the principal moments of that 2x2 block are 1 +- 5, so -4.
  const std::string f = bad("not_psd_inertia.urdf");
  expectMessage(errorOf([] { urdf("not_psd_inertia.urdf"); }),
                {at(f, "\"bent_link\""), "link 'bent_link'", "not positive semi-definite", "-4"});
}

TEST(BadUrdf, ZeroLengthAxis) {
  const std::string f = bad("zero_axis.urdf");
  expectMessage(errorOf([] { urdf("zero_axis.urdf"); }), {at(f, "\"null_axis_joint\""), "joint 'null_axis_joint'", "zero length"});
}

TEST(BadUrdf, HostileNameIsEscapedAndCut) {
  // A 10 kB joint name with a newline: the message stays one line and short.
  const std::string name = "evil&#10;" + std::string(10000, 'x');  // &#10; survives attribute normalisation
  const std::string xml = "<robot name='r'><link name='a'/><link name='b'/><joint name='" + name +
                          "' type='planar'><parent link='a'/><child link='b'/></joint></robot>";
  const std::string m = errorOf([&] { parseUrdf(xml, "inline.urdf", false); });
  expectMessage(m, {"inline.urdf", "joint 'evil\\x0a", "planar joint with <axis> [1, 0, 0]"});  // urdfdom's default axis
  EXPECT_LT(m.size(), 400u) << m;  // quoted() shows 80 characters of a name
}

// --- layout ------------------------------------------------------------------

TEST(BadLayout, MissingFile) {
  expectMessage(errorOf([] { withLayout("does_not_exist.yaml"); }), {bad("does_not_exist.yaml") + ": ", "cannot open the layout file: No such file or directory"});
}

TEST(BadLayout, UnknownLink) {
  const std::string f = bad("unknown_link.yaml");
  expectMessage(errorOf([] { withLayout("unknown_link.yaml"); }),
                {at(f, "no_such_link") + ": ", "constraints[0] 'grip'", "'no_such_link'", good("arm3.urdf"), "(closest: 'base_link', "});
}

// Issue 18 item 8: the line of `link:` and the three links of arm3.urdf closest
// to the typo. Edit distances from 'uper_arm' (insertions, deletions,
// substitutions, neighbour swaps; the recurrence run by hand in python):
// upper_arm 1 (insert p), forearm 4 (one path: u->f, p->o, swap "er" to "re",
// delete '_'), hand 7, base_link 8, tool 8; hence upper_arm, forearm, hand.
TEST(BadLayout, UnknownLinkNamesTheLineAndTheClosestLinks) {
  const std::string f = bad("unknown_link_typo.yaml");
  expectMessage(errorOf([] { withLayout("unknown_link_typo.yaml"); }),
                {at(f, "link: uper_arm") + ": constraints[0] 'grip': link 'uper_arm' is not in " + good("arm3.urdf") +
                 " (closest: 'upper_arm', 'forearm', 'hand')"});
}

TEST(BadLayout, DuplicateConstraintNames) {
  const std::string f = bad("duplicate_names.yaml");
  expectMessage(errorOf([] { withLayout("duplicate_names.yaml"); }), {at(f, "link: hand"), "constraints[1]", "duplicate", "'grip'"});
}

TEST(BadLayout, UnknownConstraintType) {
  const std::string f = bad("unknown_constraint_type.yaml");
  expectMessage(errorOf([] { withLayout("unknown_constraint_type.yaml"); }),
                {at(f, "4d"), "constraints[0] 'grip'.type", "'4d'"});
}

TEST(BadLayout, UnknownKey) {
  const std::string f = bad("unknown_key.yaml");
  expectMessage(errorOf([] { withLayout("unknown_key.yaml"); }), {at(f, "iteration:"), "unknown key 'iteration'"});
}

TEST(BadLayout, MalformedYaml) {
  expectMessage(errorOf([] { withLayout("malformed.yaml"); }), {bad("malformed.yaml") + ":", "malformed YAML"});
}

TEST(BadLayout, NonNumericMu) {
  const std::string f = bad("mu_not_number.yaml");
  expectMessage(errorOf([] { withLayout("mu_not_number.yaml"); }), {at(f, "mu:") + ": mu: ", "'fast' is not a number"});
}

TEST(BadLayout, NegativeMu) {
  const std::string f = bad("mu_negative.yaml");
  expectMessage(errorOf([] { withLayout("mu_negative.yaml"); }), {at(f, "mu:") + ": mu: ", "> 0"});
}

TEST(BadLayout, OverflowingGravity) {
  const std::string f = bad("gravity_overflow.yaml");
  expectMessage(errorOf([] { withLayout("gravity_overflow.yaml"); }), {at(f, "gravity"), "gravity", "'1e999'"});
}

TEST(BadLayout, KpWithoutTarget) {
  const std::string f = bad("kp_without_target.yaml");
  expectMessage(errorOf([] { withLayout("kp_without_target.yaml"); }), {at(f, "kp:"), "constraints[0] 'grip'", "no target"});
}

TEST(BadLayout, InlineNonFiniteOffset) {
  // yaml-cpp would read .nan as a double; the layout reader must not.
  expectMessage(errorOf([] { parseLayout("constraints:\n  - {name: c, link: tool, type: 6d, offset: {xyz: [0, .nan, 0]}}\n", "inline.yaml"); }),
                {"inline.yaml:2", "constraints[0] 'c'.offset.xyz", "'.nan'"});
}

// --- states ------------------------------------------------------------------

TEST(BadState, MissingFile) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "does_not_exist.json"); }), {bad("does_not_exist.json") + ": ", "cannot open the state file: No such file or directory"});
}

TEST(BadState, MissingJoint) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_missing_joint.json"); }),
                {bad("state_missing_joint.json") + ": q.'slide': ", "missing"});
}

TEST(BadState, UnknownJoint) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_unknown_joint.json"); }),
                {bad("state_unknown_joint.json") + ": q.'wrist': ", "not a joint"});
}

TEST(BadState, NonNumericValue) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_not_number.json"); }),
                {bad("state_not_number.json") + ": v.'elbow': ", "expected a number"});
}

TEST(BadState, OverflowingNumber) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_overflow.json"); }),
                {bad("state_overflow.json") + ": after key 'slide'", "1e999"});
}

TEST(BadState, NanLiteral) {
  // JSON has no NaN; the parser stops at it and the message says after which key.
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_nan.json"); }),
                {bad("state_nan.json") + ": after key 'shoulder'", "invalid JSON"});
}

TEST(BadState, MalformedJson) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_malformed.json"); }),
                {bad("state_malformed.json") + ": ", "invalid JSON", "line 3"});
}

TEST(BadState, ZeroNormQuaternion) {
  expectMessage(errorOf([] { states("arm3_floating.yaml", "state_zero_quaternion.json"); }),
                {bad("state_zero_quaternion.json") + ": q.'root_joint': ", "zero norm"});
}

TEST(BadState, WrongListLength) {
  expectMessage(errorOf([] { states("arm3_floating.yaml", "state_wrong_length.json"); }),
                {bad("state_wrong_length.json") + ": q.'root_joint': ",
                 "expected a list of 7 numbers [x y z qx qy qz qw] for free-flyer joint 'root_joint'", "got a list of 6"});
}

// Issue 18 item 8: the count given and the order expected, whatever was given.
TEST(BadState, FreeFlyerQGivesTheCountAndTheOrder) {
  const Model arm = loadSystem(good("arm3.urdf"), good("arm3_floating.yaml")).model;
  const std::string rest = R"(, "shoulder": 0.3, "elbow": -0.5, "slide": 0.05}, "v": {"root_joint": [0, 0, 0, 0, 0, 0],)"
                           R"( "shoulder": 0.1, "elbow": 0.2, "slide": -0.1}})";
  for (const auto& [root, got] : std::vector<std::pair<std::string, std::string>>{
           {"[0, 0, 1, 0]", "got a list of 4"}, {"[0, 0, 0.5, 0, 0, 0, 1, 0]", "got a list of 8"}, {"0.5", "got number"},
           {"{\"x\": 0}", "got object"}}) {
    test::TempFile state(".json");
    state.write(R"({"q": {"root_joint": )" + root + rest);
    expectMessage(errorOf([&] { loadStates(arm, state.path()); }),
                  {state.path() + ": q.'root_joint': expected a list of 7 numbers [x y z qx qy qz qw]", got});
  }
}

TEST(BadState, BadItemOfAList) {
  expectMessage(errorOf([] { states("arm3_tool.yaml", "state_list_second_bad.json"); }),
                {bad("state_list_second_bad.json") + ": [1]: 'torque'", "unknown key"});
}

// --- the binary: exit code, stderr, empty stdout -------------------------------

ProcessResult runProxgen(const std::vector<std::string>& args) { return test::runProgram(PROXGEN_BINARY_PATH, args); }

/// Exit 1, stdout empty, stderr exactly one "proxgen: error:" line holding every part.
void expectRefused(const ProcessResult& r, std::initializer_list<std::string> parts) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.out, "") << "partial output on stdout";
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.rfind("proxgen: error: ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  for (const std::string& part : parts) EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
}

const std::vector<std::string> kEvalArm = {"eval", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--state", good("arm3_state.json")};

std::vector<std::string> evalArmWith(std::initializer_list<std::string> extra) {
  std::vector<std::string> args = kEvalArm;
  args.insert(args.end(), extra);
  return args;
}

TEST(BadInputCli, CheckMissingUrdf) {
  expectRefused(runProxgen({"check", bad("does_not_exist.urdf")}), {bad("does_not_exist.urdf"), "cannot open the URDF file: No such file or directory"});
}

TEST(BadInputCli, CheckLayoutWithUnknownLink) {
  expectRefused(runProxgen({"check", good("arm3.urdf"), "--layout", bad("unknown_link.yaml")}),
                {bad("unknown_link.yaml"), "constraints[0] 'grip'", "'no_such_link'"});
}

TEST(BadInputCli, CheckFloatingFlagAgainstFixedLayout) {
  expectRefused(runProxgen({"check", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--floating"}),
                {"--floating", good("arm3_tool.yaml")});
}

TEST(BadInputCli, EvalSecondStateBadPrintsNothing) {
  // The first state is fine: a partial answer must still not reach stdout.
  expectRefused(runProxgen({"eval", good("arm3.urdf"), "--layout", good("arm3_tool.yaml"), "--state", bad("state_list_second_bad.json")}),
                {bad("state_list_second_bad.json"), "[1]", "'torque'"});
}

TEST(BadInputCli, EvalZeroQuaternion) {
  expectRefused(runProxgen({"eval", good("arm3.urdf"), "--layout", good("arm3_floating.yaml"), "--state", bad("state_zero_quaternion.json")}),
                {bad("state_zero_quaternion.json"), "q.'root_joint'", "zero norm"});
}

TEST(BadInputCli, EvalBadMu) {
  expectRefused(runProxgen(evalArmWith({"--mu", "nan"})), {"--mu", "'nan'", "not finite"});
  expectRefused(runProxgen(evalArmWith({"--mu", "-1"})), {"--mu", "> 0"});
  expectRefused(runProxgen(evalArmWith({"--mu", "0"})), {"--mu", "> 0"});
  expectRefused(runProxgen(evalArmWith({"--mu", "fast"})), {"--mu", "'fast' is not a number"});
  expectRefused(runProxgen(evalArmWith({"--mu", "1e999"})), {"--mu", "out of range"});
}

TEST(BadInputCli, EvalBadIterations) {
  expectRefused(runProxgen(evalArmWith({"--iterations", "-1"})), {"--iterations", "outside [0, 1000000]"});
  expectRefused(runProxgen(evalArmWith({"--iterations", "1000001"})), {"--iterations", "outside [0, 1000000]"});
  expectRefused(runProxgen(evalArmWith({"--iterations", "2.5"})), {"--iterations", "not an integer"});
}

TEST(BadInputCli, EvalUnknownAlgorithm) {
  expectRefused(runProxgen(evalArmWith({"--algorithm", "rk4"})), {"--algorithm", "'rk4'"});
}

}  // namespace
}  // namespace proxgen

// URDF loading on its own (model/urdf.cpp), not through the CLI: fixed-joint
// merging of inertias and frames against a derivation by hand, joint types,
// axes, limits, the order of bodies and the q/v slots.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "model/urdf.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

// base --j1 (revolute, y, at z = 1)--> a --f (fixed, x = 1, yaw 90 deg)--> b --j2 (prismatic, at z = 0.3)--> c
// and a second branch base --j0 (continuous)--> d, first in joint-name order.
const char* kRobot = R"(<?xml version="1.0"?>
<robot name="merge">
  <link name="base"><inertial><mass value="5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="2" velocity="3" effort="40"/></joint>
  <link name="a"><inertial><origin xyz="0 0 0.5"/><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/></inertial></link>
  <joint name="f" type="fixed"><parent link="a"/><child link="b"/><origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <link name="b"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 2"/><limit lower="0" upper="0.5" velocity="1" effort="100"/></joint>
  <link name="c"><inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="j0" type="continuous"><parent link="base"/><child link="d"/><origin xyz="0 1 0"/><axis xyz="1 0 0"/></joint>
  <link name="d"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>
)";

// Every number below is a sum or product of a few decimals, so the loader's
// answer carries a few roundings of values of size <= 2: 1e-15 absolute.
constexpr double kTol = 1e-15;

TEST(UrdfLoad, BodiesAreDepthFirstInJointNameOrder) {
  const Model m = parseUrdf(kRobot, "merge.urdf", false);
  // base is the world (fixed base); j0 < j1 by name, so d comes first, then a, then c under a.
  ASSERT_EQ(m.numBodies(), 4);
  EXPECT_EQ(m.bodies[1].link, "d");
  EXPECT_EQ(m.bodies[2].link, "a");
  EXPECT_EQ(m.bodies[3].link, "c");
  EXPECT_EQ(m.bodies[1].parent, 0);
  EXPECT_EQ(m.bodies[2].parent, 0);
  EXPECT_EQ(m.bodies[3].parent, 2);
  EXPECT_EQ(m.nq, 3);
  EXPECT_EQ(m.nv, 3);
  for (int i = 1; i < 4; ++i) {
    EXPECT_EQ(m.bodies[i].joint.idx_q, i - 1);
    EXPECT_EQ(m.bodies[i].joint.idx_v, i - 1);
  }
  EXPECT_EQ(m.name, "merge");
  EXPECT_EQ(m.sourcePath, "merge.urdf");
}

TEST(UrdfLoad, JointTypesAxesAndLimits) {
  const Model m = parseUrdf(kRobot, "merge.urdf", false);
  const Joint& j0 = m.bodies[1].joint;  // continuous: a revolute joint without position limits
  EXPECT_EQ(j0.type, JointType::Revolute);
  EXPECT_EQ(j0.urdfType, "continuous");
  EXPECT_FALSE(j0.hasPositionLimits);
  EXPECT_EQ(j0.axis, Vec3(1, 0, 0));
  const Joint& j1 = m.bodies[2].joint;
  EXPECT_EQ(j1.type, JointType::Revolute);
  EXPECT_EQ(j1.urdfType, "revolute");
  EXPECT_TRUE(j1.hasPositionLimits);
  EXPECT_EQ(j1.lower, -1.5);
  EXPECT_EQ(j1.upper, 2.0);
  EXPECT_EQ(j1.velocityLimit, 3.0);
  EXPECT_EQ(j1.effortLimit, 40.0);
  EXPECT_EQ(j1.axis, Vec3(0, 1, 0));
  const Joint& j2 = m.bodies[3].joint;  // the axis (0, 0, 2) is normalised, exactly
  EXPECT_EQ(j2.type, JointType::Prismatic);
  EXPECT_EQ(j2.axis, Vec3(0, 0, 1));
  EXPECT_EQ(j2.upper, 0.5);
  // Tree placements: j1 at z = 1 on the world; j0 at y = 1.
  EXPECT_EQ(m.bodies[2].treePlacement.p, Vec3(0, 0, 1));
  EXPECT_EQ(m.bodies[1].treePlacement.p, Vec3(0, 1, 0));
}

TEST(UrdfLoad, FixedJointMergesFrameAndInertiaAsDerivedByHand) {
  const Model m = parseUrdf(kRobot, "merge.urdf", false);
  // The fixed joint f: b is a frame on body 2 (a), at x = 1 turned 90 deg about
  // z. Rz(90) = [[0,-1,0],[1,0,0],[0,0,1]]; cos(pi/2) = 6e-17 is snapped to 0.
  const int fb = m.findFrame("b");
  ASSERT_GE(fb, 0);
  EXPECT_EQ(m.frames[fb].body, 2);
  EXPECT_EQ(m.frames[fb].viaJoint, "f");
  Mat3 Rz;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_EQ(m.frames[fb].placement.R, Rz);
  EXPECT_EQ(m.frames[fb].placement.p, Vec3(1, 0, 0));
  EXPECT_EQ(m.frames[m.findFrame("base")].body, 0);
  EXPECT_EQ(m.frames[m.findFrame("a")].body, 2);
  EXPECT_EQ(m.frames[m.findFrame("c")].body, 3);
  // j2 hangs from b: its placement in body a is f's placement times its own
  // origin, p = (1, 0, 0) + Rz (0, 0, 0.3) = (1, 0, 0.3), R = Rz.
  EXPECT_EQ(m.bodies[3].treePlacement.R, Rz);
  EXPECT_LE((m.bodies[3].treePlacement.p - Vec3(1, 0, 0.3)).cwiseAbs().maxCoeff(), kTol);

  // Body a = link a + link b. In a's frame, b's centre of mass is (1, 0, 0) +
  // Rz (0.2, 0, 0) = (1, 0.2, 0) and its tensor Rz diag(0.01, 0.02, 0.03) Rz^T
  // = diag(0.02, 0.01, 0.03) (x and y swap). Mass 2 + 1 = 3; first moment
  // 2 (0, 0, 0.5) + 1 (1, 0.2, 0) = (1, 0.2, 1). Rotational inertia about a's
  // origin, sum of Ic + m (|c|^2 1 - c c^T):
  //   a: diag(0.1, 0.2, 0.3) + 2 (0.25 1 - diag(0, 0, 0.25)) = diag(0.6, 0.7, 0.3)
  //   b: diag(0.02, 0.01, 0.03) + (1.04 1 - [[1, 0.2, 0], [0.2, 0.04, 0], [0, 0, 0]])
  //      = [[0.06, -0.2, 0], [-0.2, 1.01, 0], [0, 0, 1.07]]
  //   sum: [[0.66, -0.2, 0], [-0.2, 1.71, 0], [0, 0, 1.37]]
  const Inertia& I = m.bodies[2].inertia;
  EXPECT_NEAR(I.mass, 3.0, kTol);
  EXPECT_LE((I.mass * I.com - Vec3(1, 0.2, 1)).cwiseAbs().maxCoeff(), kTol);
  Mat3 aboutOrigin;
  aboutOrigin << 0.66, -0.2, 0, -0.2, 1.71, 0, 0, 0, 1.37;
  const Mat3 got = I.Ic + I.mass * (I.com.squaredNorm() * Mat3::Identity() - I.com * I.com.transpose());
  EXPECT_LE((got - aboutOrigin).cwiseAbs().maxCoeff(), 4 * kTol) << got;  // a few more roundings (sums of 1.04-sized terms)
  // The spatial inertia agrees: its angular block is that matrix, its coupling m [c]x.
  const Mat6 S = I.matrix();
  EXPECT_LE((S.bottomRightCorner<3, 3>() - aboutOrigin).cwiseAbs().maxCoeff(), 4 * kTol);
  EXPECT_LE((S.bottomLeftCorner<3, 3>() - skew(Vec3(1, 0.2, 1))).cwiseAbs().maxCoeff(), kTol);
  // The unmerged bodies keep their own.
  EXPECT_EQ(m.bodies[3].inertia.mass, 0.5);
  EXPECT_EQ(m.bodies[1].inertia.mass, 1.0);
}

// Quarter turns written to 11-12 digits (1.57079632679: 4.9e-12 from pi/2,
// 3.14159265359: 2.1e-12 from pi; Talos' file) leave entries of 1e-12 in the
// rotation, which the generated code carried as live terms. A rotation within
// 1e-10 of a signed permutation is that permutation (model/urdf.cpp,
// snapRotation); a quarter turn of fewer digits (1.5708: 3.7e-6 off) is the
// file's number, not round-off, and a rotation mixing a quarter turn with
// another angle keeps its entries.
TEST(UrdfLoad, QuarterTurnsOfElevenDigitsAreExact) {
  const char* urdf = R"(<?xml version="1.0"?>
<robot name="turns">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="f1" type="fixed"><parent link="base"/><child link="talos"/><origin xyz="0 0 0" rpy="3.14159265359 0 1.57079632679"/></joint>
  <link name="talos"/>
  <joint name="f2" type="fixed"><parent link="base"/><child link="short"/><origin xyz="0 0 0" rpy="0 0 1.5708"/></joint>
  <link name="short"/>
  <joint name="f3" type="fixed"><parent link="base"/><child link="mixed"/><origin xyz="0 0 0" rpy="1.57079632679 0 0.5"/></joint>
  <link name="mixed"/>
</robot>
)";
  const Model m = parseUrdf(urdf, "turns.urdf", false);
  // Rz(pi/2) Rx(pi) = [[0,-1,0],[1,0,0],[0,0,1]] diag(1,-1,-1), exactly.
  Mat3 P;
  P << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  EXPECT_EQ(m.frames[m.findFrame("talos")].placement.R, P);
  // cos(1.5708) = -3.7e-6 is kept: the file says 1.5708.
  const Mat3& S = m.frames[m.findFrame("short")].placement.R;
  EXPECT_NEAR(S(0, 0), std::cos(1.5708), 1e-15);
  EXPECT_NE(S(0, 0), 0.0);
  // The mixed turn: Rz(0.5) Rx(1.57079632679); its (2, 1) entry -sin(1.57079632679) and (2, 2)
  // entry cos(1.57079632679) = 4.9e-12 stay as computed, and the matrix a rotation to round-off.
  const Mat3& X = m.frames[m.findFrame("mixed")].placement.R;
  EXPECT_NEAR(X(2, 2), std::cos(1.57079632679), 1e-15);
  EXPECT_GT(X(2, 2), 1e-12);
  EXPECT_LE((X * X.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(UrdfLoad, FloatingBaseAddsAFreeFlyerRoot) {
  const Model m = parseUrdf(kRobot, "merge.urdf", true);
  ASSERT_EQ(m.numBodies(), 5);
  const Joint& root = m.bodies[1].joint;
  EXPECT_EQ(root.name, "root_joint");
  EXPECT_EQ(root.type, JointType::FreeFlyer);
  EXPECT_EQ(root.nq, 7);
  EXPECT_EQ(root.nv, 6);
  EXPECT_EQ(m.bodies[1].link, "base");
  EXPECT_EQ(m.bodies[1].inertia.mass, 5.0);  // the root link moves now
  EXPECT_EQ(m.frames[m.findFrame("base")].body, 1);
  EXPECT_EQ(m.nq, 10);
  EXPECT_EQ(m.nv, 9);
  EXPECT_EQ(m.bodies[2].joint.idx_q, 7);
  EXPECT_EQ(m.bodies[2].joint.idx_v, 6);
  const VecX q0 = m.neutral();
  EXPECT_EQ(q0[6], 1.0);  // identity quaternion [qx qy qz qw]
  EXPECT_EQ(q0.head<6>(), VecX::Zero(6));
}

// Four rotors of 0.055 kg fixed to a trunk at (+-0.125, +-0.049, 0), turned
// by pitch pi/2 (the example quadruped's trunk): in exact arithmetic their
// first moments and products of inertia cancel, and the merged trunk is
// diagonal with its centre of mass at the origin. The floating-point sum
// leaves residues (2^-64 = 5.4e-20 in I_xy, which the generated code printed
// as a live term). Merging snaps what is below 4 eps of the magnitudes summed
// (model/urdf.cpp, mergeInertia): those entries are exactly 0, every other
// entry is the plain sum's, within that same bound.
TEST(UrdfLoad, MergedInertiaRoundOffIsSnappedToExactZeros) {
  std::string urdf = R"(<?xml version="1.0"?>
<robot name="rotors">
  <link name="trunk"><inertial><mass value="3.3"/><inertia ixx="0.011253" ixy="0" ixz="0" iyy="0.036203" iyz="0" izz="0.042673"/></inertial></link>
  <joint name="j" type="revolute"><parent link="trunk"/><child link="leg"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <link name="leg"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
)";
  // In the quadruped's merging order (joint names LF, LH, RF, RH): the order decides the residue.
  const double xs[4] = {0.125, -0.125, 0.125, -0.125}, ys[4] = {0.049, 0.049, -0.049, -0.049};
  for (int k = 0; k < 4; ++k)
    urdf += fmt::format(R"(  <joint name="r{0}" type="fixed"><parent link="trunk"/><child link="rotor{0}"/><origin xyz="{1} {2} 0" rpy="0 1.5707963267948966 0"/></joint>
  <link name="rotor{0}"><inertial><mass value="0.055"/><inertia ixx="0.000033" ixy="0" ixz="0" iyy="0.000033" iyz="0" izz="0.000063"/></inertial></link>
)",
                        k, xs[k], ys[k]);
  urdf += "</robot>\n";
  const Model m = parseUrdf(urdf, "rotors.urdf", true);
  const Inertia& trunk = m.bodies[1].inertia;
  // The plain sum in the loader's order (joints r0..r3 by name), with the
  // rotation of pitch pi/2 snapped as the loader snaps it: Ry(90) = [[0,0,1],[0,1,0],[-1,0,0]].
  Mat3 Ry;
  Ry << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  Inertia plain{3.3, Vec3::Zero(), Vec3(0.011253, 0.036203, 0.042673).asDiagonal()};
  for (int k = 0; k < 4; ++k) {
    const Inertia rotor{0.055, Vec3::Zero(), Vec3(0.000033, 0.000033, 0.000063).asDiagonal()};
    plain = plain + rotor.transformed(SE3{Ry, Vec3(xs[k], ys[k], 0)});
  }
  // The test means something only if the plain sum does leave a residue.
  const double residue = std::max(plain.com.cwiseAbs().maxCoeff(),
                                  std::max({std::abs(plain.Ic(0, 1)), std::abs(plain.Ic(0, 2)), std::abs(plain.Ic(1, 2))}));
  ASSERT_GT(residue, 0.0) << "the plain sum cancels exactly: no round-off to snap";
  EXPECT_EQ(trunk.com, Vec3::Zero());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (r != c) {
        EXPECT_EQ(trunk.Ic(r, c), 0.0) << r << "," << c;
      }
  // The rest is the plain sum's: the snapping moved nothing above its bound,
  // 4 eps of the trace (the loader's threshold), and the mass is exact.
  const double bound = 4 * std::numeric_limits<double>::epsilon() * plain.Ic.trace();
  EXPECT_EQ(trunk.mass, plain.mass);
  EXPECT_LE((trunk.Ic - plain.Ic).cwiseAbs().maxCoeff(), bound);
  for (int k = 0; k < 3; ++k) EXPECT_GT(trunk.Ic(k, k), 0.0);
}

}  // namespace
}  // namespace proxgen

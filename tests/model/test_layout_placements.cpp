// The layout's placements (model/layout.cpp): a constraint's `offset` and
// `target` rotations are snapped as a URDF origin's are (model/spatial.hpp,
// snapRotation), so a frame turned by a quarter turn written in decimal folds
// in the generated code as it would in the URDF.
#include <gtest/gtest.h>

#include <cmath>

#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

const Constraint& only(const Layout& L) {
  EXPECT_EQ(L.constraints.size(), 1u);
  return L.constraints.front();
}

Mat3 offsetOf(const std::string& rpy) {
  return only(parseLayout("constraints:\n  - {name: c, link: l, type: 6d, offset: {xyz: [0, 0, 0], rpy: " + rpy + "}}\n",
                          "l.yaml"))
      .offset.R;
}

// Rz(pi/2) exactly, whether pi/2 is the nearest double (cos = 6.1e-17, the
// entry-wise snap) or written to 11 digits (4.9e-12 off, the whole-rotation one).
TEST(LayoutPlacements, QuarterTurnsAreExactAsInAUrdf) {
  Mat3 Rz;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_EQ(offsetOf("[0, 0, 1.5707963267948966]"), Rz);
  EXPECT_EQ(offsetOf("[0, 0, 1.57079632679]"), Rz);
  // A target's rotation too: pi about x, 12 digits.
  const Layout L = parseLayout(
      "constraints:\n  - {name: c, link: l, type: 6d, kp: 10, target: {xyz: [0, 0, 1], rpy: [3.14159265359, 0, 0]}}\n",
      "l.yaml");
  const Constraint& c = only(L);
  EXPECT_EQ(c.target.R, Vec3(1, -1, -1).asDiagonal().toDenseMatrix());
}

// What the file says stays: 1.5708 is 3.7e-6 from pi/2, and a general angle
// is not touched.
TEST(LayoutPlacements, OtherAnglesAreTheFilesNumbers) {
  const Mat3 R = offsetOf("[0, 0, 1.5708]");
  EXPECT_NEAR(R(0, 0), std::cos(1.5708), 1e-15);
  EXPECT_NE(R(0, 0), 0.0);
  EXPECT_EQ(offsetOf("[0.3, -0.2, 0.1]"), rpyToMatrix(Vec3(0.3, -0.2, 0.1)));
}

}  // namespace
}  // namespace proxgen

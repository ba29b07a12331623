// The per-body rotation matrices are two-dimensional workspace members,
// `Scalar RJ_<body>[3][3]` and `oR_<body>[3][3]` (row r, column c), with the
// memory layout the flat row-major `[9]` had (a `Scalar[3][3]` is nine
// contiguous Scalars in row-major order), so the compiled code is the same.
#include <gtest/gtest.h>

#include <regex>

#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

GenerateOptions example(const std::string& robot, const std::string& layout) {
  GenerateOptions g;
  const std::string dir = test::sourceDir() + "/generated/" + robot;
  g.urdf = dir + "/" + robot + ".urdf";
  g.layout = layout;
  g.name = robot;
  return g;
}

// How many workspace members named <prefix>_<body> are declared as `[dims]`.
int declared(const std::string& header, const std::string& prefix, const std::string& dims) {
  const std::regex re("Scalar " + prefix + "_\\w+" + dims + ";");
  return int(std::distance(std::sregex_iterator(header.begin(), header.end(), re), std::sregex_iterator()));
}

TEST(WorkspaceMembers, RotationsAreThreeByThree) {
  // The quadruped's free flyer stores RJ (its rotation from the quaternion), and
  // its tilted hip axes too; the arm with gains stores oR (world placement of
  // the bodies under a kp constraint).
  const std::string dir = test::sourceDir();
  const SolverFiles quad = generateFiles(example("quadruped", dir + "/generated/quadruped/layout.yaml"));
  const SolverFiles arm = generateFiles(example("arm", dir + "/tests/generated/layouts/arm_gains.yaml"));
  EXPECT_GT(declared(quad.header, "RJ", R"(\[3\]\[3\])"), 0);
  EXPECT_GT(declared(arm.header, "oR", R"(\[3\]\[3\])"), 0);
  for (const SolverFiles* f : {&quad, &arm}) {
    for (const char* p : {"RJ", "oR"}) {
      EXPECT_EQ(declared(f->header, p, R"(\[9\])"), 0) << p << " still flat";
      // Every access reads or writes an entry (r, c): no flat index is left.
      const std::regex flat("w\\." + std::string(p) + "_\\w+\\[\\d+\\](?!\\[)");
      EXPECT_FALSE(std::regex_search(f->source, flat)) << p << " indexed flat";
    }
  }
  // Entry (2, 1) of the free flyer's rotation, row-major k = 7 before:
  // 2 (y z + x w) with q = [x y z qx qy qz qw] (Eigen's toRotationMatrix), of
  // the normalised quaternion qu0..qu3 (pass_kinematics.cpp).
  EXPECT_NE(quad.source.find("w.RJ_trunk[2][1] = 2.0*(qu1*qu2 + qu0*qu3);"), std::string::npos);
}

}  // namespace
}  // namespace proxgen::emit

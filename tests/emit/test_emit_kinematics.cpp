// The kinematics pass's choice of sine and cosine (emit/pass_kinematics.cpp,
// sincosCalled): the runtime's sincos inlined at each revolute joint on a
// robot of four revolute joints or fewer, or its called form from five on,
// whose run computes them in two lanes at the x86-64 baseline
// (docs/benchmarks.md, "The called form from five revolute joints"); and
// before each pass of joint transforms the run of every joint (sincosRuns,
// lanes.hpp's sincos_run). They give the same bits (tests/runtime); this
// checks which one the generated source uses, that every joint uses it, and
// where the joint transforms go with each.
#include <gtest/gtest.h>

#include <string>

#include "emit/batch.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The source as the passes printed it, before blocks equal up to their
// constants become shared kernels (emit/shared_blocks.hpp), which would print
// the one joint's statements once for all the joints it runs.
std::string chainSource(int links, const std::string& functions = "") {
  return test::syntheticChainFiles(links, functions).unsharedSource;
}

TEST(KinematicsCode, SinCosIsCalledFromFiveRevoluteJointsOn) {
  const std::string four = chainSource(5), five = chainSource(6);
  EXPECT_EQ(test::occurrences(four, "proxgen_rt::sincos_joint(q["), 4);
  EXPECT_EQ(test::occurrences(four, "proxgen_rt::sincos_joint_called("), 0);
  EXPECT_EQ(test::occurrences(five, "proxgen_rt::sincos_joint_called(q["), 5);
  EXPECT_EQ(test::occurrences(five, "proxgen_rt::sincos_joint("), 0);
  // Each form's run says which form its joints take (lanes.hpp: the x86-64
  // baseline runs in two lanes before called joints only).
  EXPECT_EQ(test::occurrences(four, "proxgen_rt::sincos_run<4>("), 1);
  EXPECT_EQ(test::occurrences(five, "proxgen_rt::sincos_run<5, true>("), 1);
  // The lane code inlines the kernel again (batch.cpp: the call was slower there).
  const std::string lanes = batchFiles(test::syntheticChainFiles(18), 4).source;
  EXPECT_EQ(test::occurrences(lanes, "sincos_joint_called"), 0);
  EXPECT_EQ(test::occurrences(lanes, "proxgen_rt::sincos_joint(q["), 17);
}

// The chain's angles are q[0..n): one run of all of them before the kinematics
// (slots 0..n of w.sq and w.cq), which the joints' calls then read.
TEST(KinematicsCode, OneSinCosRunOfTheConsecutiveAnglesPrecedesTheKinematics) {
  const std::string src = chainSource(18);
  EXPECT_EQ(test::occurrences(src, "proxgen_rt::sincos_run<"), 1);
  const auto run = src.find("proxgen_rt::sincos_run<17, true>(&q[0], &w.sq[0], &w.cq[0]);");
  ASSERT_NE(run, std::string::npos);
  const auto host = src.rfind("void kinematics(");  // the host, after its parts
  EXPECT_GT(run, host);
  EXPECT_LT(run, src.find("kinematics_", host));  // before its first part's call
  for (int j = 0; j < 17; ++j)
    EXPECT_EQ(test::occurrences(src, "proxgen_rt::sincos_joint_called(q[" + std::to_string(j) + "], w.sq[" + std::to_string(j) +
                             "], w.cq[" + std::to_string(j) + "]);"),
              1)
        << "joint " << j;
}

// Where sincos is inlined, the kinematics pass and inverse_dynamics' sweep
// compute every joint transform first, in a pass of their own (part functions
// named <host>_transforms_...); where it is called, each body's step computes
// its own (jointTransformsFirst: the faster way for each, docs/benchmarks.md).
TEST(KinematicsCode, TheJointTransformsComeFirstWhereSinCosIsInlined) {
  const std::string functions = "constrained_aba,prox_pv,inverse_dynamics";
  const std::string inlined = chainSource(5, functions), called = chainSource(6, functions);
  EXPECT_GT(test::occurrences(inlined, "void kinematics_transforms_"), 0);
  EXPECT_GT(test::occurrences(inlined, "void rnea_transforms_"), 0);
  EXPECT_EQ(test::occurrences(called, "void kinematics_transforms_"), 0);
  EXPECT_EQ(test::occurrences(called, "void rnea_transforms_"), 0);
}

}  // namespace
}  // namespace proxgen::emit

// The plan (emit/plan.hpp) is what generation decides: it must agree with what
// the generic solvers compute at run time (System::supportBodies, the rows of
// each subtree in Data), on the shared cases and the repository's robots.
#include <gtest/gtest.h>

#include <set>

#include "algorithms/data.hpp"
#include "emit/plan.hpp"
#include "cases/cases.hpp"
#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

std::vector<std::pair<std::string, System>> systems() {
  std::vector<std::pair<std::string, System>> out;
  for (const char* robot : {"arm", "quadruped", "humanoid"}) {
    const std::string dir = test::sourceDir() + "/generated/" + robot;
    out.emplace_back(robot, loadSystem(dir + "/" + robot + ".urdf", dir + "/layout.yaml"));
  }
  for (const Case& c : test::sharedCases()) out.emplace_back(c.name, loadCaseSystem(c));
  return out;
}

TEST(Plan, AgreesWithTheGenericSolversRunTimeView) {
  for (const auto& [name, sys] : systems()) {
    SCOPED_TRACE(name);
    const Plan plan = makePlan(sys, name, ScalarType::Double);
    const Data d(sys);
    EXPECT_EQ(plan.support, sys.supportBodies());
    EXPECT_EQ(plan.nq, sys.model.nq);
    EXPECT_EQ(plan.nv, sys.model.nv);
    EXPECT_EQ(plan.nc, sys.nc);
    ASSERT_EQ(int(plan.bodies.size()), sys.model.numBodies());
    std::set<int> all(plan.support.begin(), plan.support.end());
    for (int i : plan.offSupport) EXPECT_TRUE(all.insert(i).second) << "body " << i << " on and off the support";
    EXPECT_EQ(int(all.size()), sys.model.numBodies() - 1);
    for (int i = 0; i < sys.model.numBodies(); ++i) {
      const BodyPlan& b = plan.bodies[std::size_t(i)];
      EXPECT_EQ(b.subtreeRows, d.subtreeRows[std::size_t(i)]) << "body " << i;
      EXPECT_EQ(b.m() > 0, i == 0 || b.onSupport) << "body " << i << ": rows exactly on the support";
      if (i == 0) continue;
      // A child's rows sit at its offset in its parent's rows.
      const BodyPlan& p = plan.bodies[std::size_t(b.parent)];
      for (int r = 0; r < b.m(); ++r)
        EXPECT_EQ(p.subtreeRows[std::size_t(b.offsetInParent + r)], b.subtreeRows[std::size_t(r)]) << "body " << i;
    }
    EXPECT_EQ(plan.rootRows, d.subtreeRows[0]);
    EXPECT_EQ(int(plan.rootRows.size()), sys.nc);
    std::set<int> rows(plan.rootRows.begin(), plan.rootRows.end());
    EXPECT_EQ(int(rows.size()), sys.nc) << "every row once";
  }
}

TEST(Plan, IdentifiersAreUnique) {
  for (const auto& [name, sys] : systems()) {
    const Plan plan = makePlan(sys, name, ScalarType::Double);
    std::set<std::string> ids, cids;
    for (const BodyPlan& b : plan.bodies) EXPECT_TRUE(ids.insert(b.ident).second) << name << ": " << b.ident;
    for (const ConstraintPlan& c : plan.constraints) EXPECT_TRUE(cids.insert(c.ident).second) << name << ": " << c.ident;
  }
}

TEST(Plan, JointClassesAndZeroPatterns) {
  const std::string dir = test::sourceDir() + "/generated/";
  // The arm: six revolute joints about +z (the UR5e's URDF), a fixed base.
  const System arm = loadSystem(dir + "arm/arm.urdf", dir + "arm/layout.yaml");
  const Plan pa = makePlan(arm, "arm", ScalarType::Double);
  for (int i = 1; i < arm.model.numBodies(); ++i) {
    EXPECT_EQ(pa.bodies[std::size_t(i)].jointClass, JointClass::RevoluteZ);
    EXPECT_EQ(pa.bodies[std::size_t(i)].axisSign, 1.0);
  }
  // Every body of a fully welded chain is on the support.
  EXPECT_TRUE(pa.offSupport.empty());
  // The quadruped: a free flyer, axis-aligned joints and the tilted abduction
  // axes ("1 0 0.1") as general axes.
  const System quad = loadSystem(dir + "quadruped/quadruped.urdf", dir + "quadruped/layout.yaml");
  const Plan pq = makePlan(quad, "quadruped", ScalarType::Double);
  EXPECT_EQ(pq.bodies[1].jointClass, JointClass::FreeFlyer);
  int general = 0;
  for (const BodyPlan& b : pq.bodies) general += b.jointClass == JointClass::RevoluteAxis;
  EXPECT_EQ(general, 4);
  // Zero patterns: the free flyer's tree placement is the identity (3 non-zeros
  // of 9, none of 3), a point mass off the origin has a sparse inertia.
  EXPECT_EQ(pq.bodies[1].treeRotationNonzeros, 3);
  EXPECT_EQ(pq.bodies[1].treeTranslationNonzeros, 0);
  for (const BodyPlan& b : pq.bodies) {
    if (b.index > 0) {
      EXPECT_LE(b.inertiaNonzeros, 21);
    }
  }
}

TEST(Plan, NegativeAxesAreSignedPicks) {
  PROXGEN_REQUIRE_MODELS();
  // atlas_shadow.urdf has axes "0 -1.0 0" and "-0.0 -1.0 -0.0": about -y.
  for (const Case& c : test::sharedCases()) {
    if (c.name != "atlas_shadow_f6x2") continue;
    const System sys = loadCaseSystem(c);
    const Plan plan = makePlan(sys, c.name, ScalarType::Double);
    int negative = 0;
    for (int i = 1; i < sys.model.numBodies(); ++i) {
      const BodyPlan& b = plan.bodies[std::size_t(i)];
      const Vec3& a = sys.model.bodies[std::size_t(i)].joint.axis;
      if (b.axis < 0) continue;
      EXPECT_EQ(a[b.axis], b.axisSign) << b.joint;
      negative += b.axisSign < 0;
    }
    EXPECT_GT(negative, 0);
  }
}

}  // namespace
}  // namespace proxgen::emit

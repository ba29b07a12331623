// The plan (emit/plan.hpp) is what generation decides. Its tree facts come
// from one place (model/tree.cpp, ConstraintTree), which the generic solvers
// read too, so comparing the plan with Data would compare a value with
// itself: each fact is checked against a derivation of its own here, from the
// parent links and the constraints alone, on the shared cases and the
// repository's robots.
#include <gtest/gtest.h>
#include <fmt/format.h>

#include <algorithm>
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

// Body b is in the subtree of body i (b == i or i is an ancestor of b).
bool inSubtree(const Model& m, int b, int i) {
  for (; b >= 0; b = m.bodies[std::size_t(b)].parent)
    if (b == i) return true;
  return false;
}

TEST(Plan, TreeFactsAgreeWithAnIndependentDerivation) {
  for (const auto& entry : systems()) {
    // Named, not a structured binding: the lambdas below capture it (C++17).
    const std::string& name = entry.first;
    const System& sys = entry.second;
    SCOPED_TRACE(name);
    const Model& m = sys.model;
    const int N = m.numBodies();
    const Plan plan = makePlan(sys, name, ScalarType::Double);
    ASSERT_EQ(int(plan.bodies.size()), N);
    // Sizes: sums over the joints and the constraints (not the copies makePlan reads).
    int nq = 0, nv = 0, nc = 0;
    for (int i = 1; i < N; ++i) nq += m.bodies[std::size_t(i)].joint.nq, nv += m.bodies[std::size_t(i)].joint.nv;
    for (const Constraint& c : sys.constraints) nc += c.rows();
    EXPECT_EQ(plan.nq, nq);
    EXPECT_EQ(plan.nv, nv);
    EXPECT_EQ(plan.nc, nc);
    // The support: the moving bodies with a constrained body in their subtree.
    std::vector<int> support;
    for (int i = 1; i < N; ++i) {
      bool constrained = false;
      for (const Constraint& c : sys.constraints) constrained |= inSubtree(m, c.body, i);
      if (constrained) support.push_back(i);
    }
    // The sweep: every moving body once, breadth first (the depth never
    // decreases); in a depth the bodies of one shape one after the other, in
    // their parents' order (siblings in child order), so that the same link of
    // two limbs comes one after the other.
    ASSERT_EQ(int(plan.sweep.size()), N - 1);
    std::vector<int> depth(std::size_t(N), 0), at(std::size_t(N), -1);
    for (int i = 1; i < N; ++i) depth[std::size_t(i)] = depth[std::size_t(m.bodies[std::size_t(i)].parent)] + 1;
    for (std::size_t k = 0; k < plan.sweep.size(); ++k) {
      ASSERT_EQ(at[std::size_t(plan.sweep[k])], -1) << "body " << plan.sweep[k] << " twice";
      at[std::size_t(plan.sweep[k])] = int(k);
    }
    std::set<std::pair<int, std::string>> done;  // (depth, shape) runs already closed
    for (std::size_t k = 1; k < plan.sweep.size(); ++k) {
      const int a = plan.sweep[k - 1], b = plan.sweep[k];
      const BodyPlan &pa = plan.bodies[std::size_t(a)], &pb = plan.bodies[std::size_t(b)];
      EXPECT_LE(depth[std::size_t(a)], depth[std::size_t(b)]) << a << " before " << b;
      if (depth[std::size_t(a)] != depth[std::size_t(b)] || pa.shape != pb.shape) {
        EXPECT_TRUE(done.insert({depth[std::size_t(a)], pa.shape}).second) << "body " << a << ": its shape's run is split";
        continue;
      }
      EXPECT_LE(at[std::size_t(pa.parent)], at[std::size_t(pb.parent)]) << a << " before " << b;
      if (pa.parent == pb.parent) EXPECT_LT(a, b);
    }
    // The support and the other bodies, in the sweep's order.
    std::vector<int> supportInSweep;
    for (int i : plan.sweep)
      if (std::find(support.begin(), support.end(), i) != support.end()) supportInSweep.push_back(i);
    EXPECT_EQ(plan.support, supportInSweep);
    for (std::size_t k = 1; k < plan.offSupport.size(); ++k)
      EXPECT_LT(at[std::size_t(plan.offSupport[k - 1])], at[std::size_t(plan.offSupport[k])]);
    std::set<int> all(plan.support.begin(), plan.support.end());
    for (int i : plan.offSupport) EXPECT_TRUE(all.insert(i).second) << "body " << i << " on and off the support";
    EXPECT_EQ(int(all.size()), N - 1);
    // Bodies are numbered depth first, children in order: a subtree is a
    // contiguous index range, so its rows in tree order are the rows of the
    // constraints in that range sorted by (body, row).
    for (int i = 0; i < N; ++i) {
      const auto& ch = m.bodies[std::size_t(i)].children;
      for (std::size_t k = 1; k < ch.size(); ++k) ASSERT_LT(ch[k - 1], ch[k]) << "body " << i << ": children out of order";
    }
    auto rowsOf = [&](int i) {
      std::vector<std::pair<int, int>> keyed;
      for (const Constraint& c : sys.constraints)
        if (inSubtree(m, c.body, i))
          for (int r = 0; r < c.rows(); ++r) keyed.push_back({c.body, c.row + r});
      std::sort(keyed.begin(), keyed.end());
      std::vector<int> rows;
      for (const auto& kr : keyed) rows.push_back(kr.second);
      return rows;
    };
    const std::vector<int> root = rowsOf(0);
    EXPECT_EQ(plan.rootRows, root);
    ASSERT_EQ(int(plan.rowPosition.size()), nc);
    for (int t = 0; t < int(root.size()); ++t) EXPECT_EQ(plan.rowPosition[std::size_t(root[std::size_t(t)])], t);
    for (int i = 0; i < N; ++i) {
      const BodyPlan& b = plan.bodies[std::size_t(i)];
      const std::vector<int> rows = rowsOf(i);
      EXPECT_EQ(b.subtreeRows, rows) << "body " << i;
      EXPECT_EQ(b.m() > 0, i == 0 || b.onSupport) << "body " << i << ": rows exactly on the support";
      // Its rows are the block of the root's order that starts at rowStart.
      for (int r = 0; r < b.m(); ++r)
        EXPECT_EQ(root[std::size_t(b.rowStart + r)], rows[std::size_t(r)]) << "body " << i << ", row " << r;
      if (i == 0) continue;
      // A child's rows sit at its offset in its parent's rows.
      const BodyPlan& p = plan.bodies[std::size_t(b.parent)];
      for (int r = 0; r < b.m(); ++r)
        EXPECT_EQ(p.subtreeRows[std::size_t(b.offsetInParent + r)], b.subtreeRows[std::size_t(r)]) << "body " << i;
    }
    std::set<int> distinct(plan.rootRows.begin(), plan.rootRows.end());
    EXPECT_EQ(int(distinct.size()), nc) << "every row once";
    // A subtree's dofs are [idx_v, dofEnd): exactly the dofs of the bodies in it.
    for (int i = 0; i < N; ++i) {
      const BodyPlan& b = plan.bodies[std::size_t(i)];
      for (int j = 1; j < N; ++j) {
        const Joint& jt = m.bodies[std::size_t(j)].joint;
        for (int d = jt.idx_v; d < jt.idx_v + jt.nv; ++d)
          EXPECT_EQ(d >= b.idx_v && d < b.dofEnd, inSubtree(m, j, i)) << "body " << i << ", dof " << d;
      }
    }
  }
}

// The generic solvers' Data reads the same tree facts as the plan.
TEST(Plan, DataReadsTheSameTreeFacts) {
  for (const auto& [name, sys] : systems()) {
    SCOPED_TRACE(name);
    const Plan plan = makePlan(sys, name, ScalarType::Double);
    const Data d(sys);
    // The same bodies: Data's ascending, the plan's in the sweep's order.
    std::vector<int> support = plan.support;
    std::sort(support.begin(), support.end());
    EXPECT_EQ(d.support, support);
    for (int i = 0; i < sys.model.numBodies(); ++i) {
      EXPECT_EQ(d.subtreeRows[std::size_t(i)], plan.bodies[std::size_t(i)].subtreeRows) << "body " << i;
      EXPECT_EQ(d.subtreeStart[std::size_t(i)], plan.bodies[std::size_t(i)].rowStart) << "body " << i;
    }
  }
}

// A body's shape is its subtree's joints and constraints, not its constants:
// Talos' left and right leg links have one (their blocks can pair), a leg's and
// an arm's link of the same joint class do not; in the sweep the two legs'
// links come one after the other.
TEST(Plan, TheLegsOfTalosAreTwins) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    if (c.name != "talos_f6x2") continue;
    const Plan plan = makePlan(loadCaseSystem(c), c.name, ScalarType::Double);
    auto body = [&](const std::string& link) -> const BodyPlan& {
      for (const BodyPlan& b : plan.bodies)
        if (b.link == link) return b;
      ADD_FAILURE() << "no link " << link;
      return plan.bodies[0];
    };
    for (int k = 1; k <= 6; ++k) {
      const BodyPlan &l = body(fmt::format("leg_left_{}_link", k)), &r = body(fmt::format("leg_right_{}_link", k));
      EXPECT_EQ(l.shape, r.shape) << k;
      const auto pos = [&](int i) { return std::find(plan.sweep.begin(), plan.sweep.end(), i) - plan.sweep.begin(); };
      EXPECT_EQ(pos(r.index), pos(l.index) + 1) << k;
    }
    EXPECT_NE(body("leg_left_1_link").shape, body("arm_left_1_link").shape);  // both about z; other subtrees
    EXPECT_NE(body("leg_left_1_link").shape, body("leg_left_2_link").shape);
    return;
  }
  FAIL() << "no case talos_f6x2";
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
  bool found = false;
  for (const Case& c : test::sharedCases()) {
    if (c.name != "atlas_shadow_f6x2") continue;
    found = true;
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
  EXPECT_TRUE(found) << "atlas_shadow_f6x2 is not in cases.yaml";
}

}  // namespace
}  // namespace proxgen::emit

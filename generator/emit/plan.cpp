#include "emit/plan.hpp"

#include <fmt/format.h>

#include "emit/identifiers.hpp"

namespace proxgen::emit {

const char* jointClassName(JointClass c) {
  switch (c) {
    case JointClass::RevoluteX: return "revolute about x";
    case JointClass::RevoluteY: return "revolute about y";
    case JointClass::RevoluteZ: return "revolute about z";
    case JointClass::RevoluteAxis: return "revolute about a general axis";
    case JointClass::PrismaticX: return "prismatic along x";
    case JointClass::PrismaticY: return "prismatic along y";
    case JointClass::PrismaticZ: return "prismatic along z";
    case JointClass::PrismaticAxis: return "prismatic along a general axis";
    case JointClass::FreeFlyer: return "free flyer";
    case JointClass::Planar: return "planar";
  }
  return "?";
}

std::vector<int> pickedComponents(JointClass c) {
  if (c == JointClass::FreeFlyer) return {0, 1, 2, 3, 4, 5};
  if (c == JointClass::Planar) return {0, 1, 5};
  return {};
}

namespace {

// An axis that is exactly +-e_k (as parsed) makes S a signed unit vector.
void classify(const Joint& j, BodyPlan& b) {
  if (j.type == JointType::FreeFlyer || j.type == JointType::Planar) {
    b.jointClass = j.type == JointType::FreeFlyer ? JointClass::FreeFlyer : JointClass::Planar;
    return;
  }
  const bool revolute = j.type == JointType::Revolute;
  for (int k = 0; k < 3; ++k) {
    const bool others = j.axis[(k + 1) % 3] == 0.0 && j.axis[(k + 2) % 3] == 0.0;
    if (others && (j.axis[k] == 1.0 || j.axis[k] == -1.0)) {
      b.axis = k;
      b.axisSign = j.axis[k];
      b.jointClass = JointClass(int(revolute ? JointClass::RevoluteX : JointClass::PrismaticX) + k);
      return;
    }
  }
  b.jointClass = revolute ? JointClass::RevoluteAxis : JointClass::PrismaticAxis;
}

int countNonzeros(const Mat3& m) {
  int n = 0;
  for (int k = 0; k < 9; ++k) n += m(k / 3, k % 3) != 0.0;
  return n;
}

}  // namespace

Plan makePlan(const System& sys, const std::string& name, ScalarType scalar) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  Plan plan;
  plan.name = sanitizeIdentifier(name);
  plan.scalar = scalar;
  plan.nq = m.nq;
  plan.nv = m.nv;
  plan.nc = sys.nc;
  plan.floatingBase = m.floatingBase;
  plan.mu = sys.mu;
  plan.iterations = sys.iterations;

  IdentifierSet ids;
  plan.bodies.resize(std::size_t(N));
  for (int i = 0; i < N; ++i) {
    const Body& body = m.bodies[std::size_t(i)];
    BodyPlan& b = plan.bodies[std::size_t(i)];
    b.index = i;
    b.parent = body.parent;
    b.link = body.link;
    b.children = body.children;
    if (i == 0) {
      b.ident = ids.make("world", 0);
      continue;
    }
    b.joint = body.joint.name;
    b.ident = ids.make(body.link, i);
    classify(body.joint, b);
    b.idx_q = body.joint.idx_q;
    b.nq = body.joint.nq;
    b.idx_v = body.joint.idx_v;
    b.nv = body.joint.nv;
    b.treeRotationNonzeros = countNonzeros(body.treePlacement.R);
    for (int k = 0; k < 3; ++k) b.treeTranslationNonzeros += body.treePlacement.p[k] != 0.0;
    const Mat6 I = body.inertia.matrix();
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) b.inertiaNonzeros += I(r, c) != 0.0;
  }

  IdentifierSet cids;
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    ConstraintPlan cp;
    cp.name = c.name;
    cp.link = c.link;
    cp.ident = cids.make(c.name, int(k));
    cp.body = c.body;
    cp.row = c.row;
    cp.rows = c.rows();
    cp.weld = c.type == ConstraintType::Weld6D;
    plan.constraints.push_back(cp);
    plan.bodies[std::size_t(c.body)].constraints.push_back(int(k));
    if (c.kp != 0)
      for (int i : m.pathToRoot(c.body)) plan.bodies[std::size_t(i)].needsPlacement = true;
  }

  const ConstraintTree tree = constraintTree(sys);
  for (int i = 1; i < N; ++i) {
    BodyPlan& b = plan.bodies[std::size_t(i)];
    b.onSupport = tree.onSupport[std::size_t(i)] != 0;
    b.needsGravity = b.onSupport;
  }
  for (int i = N - 1; i >= 0; --i) {  // children after their parent: leaves first
    BodyPlan& b = plan.bodies[std::size_t(i)];
    b.shape = fmt::format("{}{}{}", int(b.jointClass), b.axis, b.onSupport ? "s" : "");
    for (int k : b.constraints) b.shape += plan.constraints[std::size_t(k)].weld ? "w" : "p";
    b.shape += "(";
    for (int c : b.children) b.shape += plan.bodies[std::size_t(c)].shape + ",";
    b.shape += ")";
    b.dofEnd = std::max(b.dofEnd, b.idx_v + b.nv);
    if (i > 0) {
      BodyPlan& parent = plan.bodies[std::size_t(b.parent)];
      parent.dofEnd = std::max(parent.dofEnd, b.dofEnd);
    }
  }
  // The sweep: breadth first, one depth after the other; in a depth, the
  // bodies of one shape together, shapes in the order they first appear (in
  // the parents' order), so that the fingers of two hands form pairs across
  // the hands too.
  for (std::vector<int> depth = plan.bodies[0].children; !depth.empty();) {
    std::vector<char> taken(depth.size(), 0);
    std::vector<int> next;
    for (std::size_t a = 0; a < depth.size(); ++a) {
      if (taken[a]) continue;
      for (std::size_t b = a; b < depth.size(); ++b) {
        if (taken[b] || plan.bodies[std::size_t(depth[b])].shape != plan.bodies[std::size_t(depth[a])].shape) continue;
        taken[b] = 1;
        plan.sweep.push_back(depth[b]);
        for (int c : plan.bodies[std::size_t(depth[b])].children) next.push_back(c);
      }
    }
    depth = std::move(next);
  }
  for (int i : plan.sweep) (plan.bodies[std::size_t(i)].onSupport ? plan.support : plan.offSupport).push_back(i);
  for (int i = 0; i < N; ++i) {
    BodyPlan& b = plan.bodies[std::size_t(i)];
    b.subtreeRows = tree.subtreeRows[std::size_t(i)];
    b.offsetInParent = tree.offsetInParent[std::size_t(i)];
    b.rowStart = tree.subtreeStart[std::size_t(i)];
  }
  // The q line of the header: the base's slots first when the layout adds one;
  // a free flyer or planar joint from the URDF is described by the joint table.
  bool multiDof = false;
  for (int i = 1; i < N; ++i) multiDof = multiDof || !pickedComponents(plan.bodies[std::size_t(i)].jointClass).empty();
  plan.qConvention = m.floatingBase ? "x y z qx qy qz qw of the base, then one value per joint"
                     : m.planarBase ? "x y cos(yaw) sin(yaw) of the base, then one value per joint"
                     : multiDof     ? "one value per one-dof joint, x y z qx qy qz qw per free flyer, x y cos(yaw) "
                                      "sin(yaw) per planar joint"
                                    : "one value per joint";
  plan.rootRows = plan.bodies[0].subtreeRows;
  plan.rowPosition = tree.treePosition;
  return plan;
}

}  // namespace proxgen::emit

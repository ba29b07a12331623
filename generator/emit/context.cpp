#include "emit/context.hpp"

#include <fmt/format.h>

#include "emit/identifiers.hpp"

namespace proxgen::emit {

std::string Emit::member(const Quantity& qy, int body, int size, int idx) {
  const std::string base = fmt::format("{}_{}", qy.prefix, bp(body).ident);
  return ws.member(base, size, idx, fmt::format("{}, body {}", qy.what, body));
}

std::string Emit::loopSlot(const Quantity& qy, int body, int size, int idx) {
  const std::string base = fmt::format("{}_{}", qy.prefix, bp(body).ident);
  return ws.loopSlot(base, size, idx, fmt::format("{}, body {}", qy.what, body));
}

std::string Emit::member(const Quantity& qy, int body, int rows, int cols, int r, int c) {
  const std::string base = fmt::format("{}_{}", qy.prefix, bp(body).ident);
  return ws.member(base, rows, cols, r, c, fmt::format("{}, body {}", qy.what, body));
}

std::string Emit::loopSlot(const Quantity& qy, int body, int rows, int cols, int r, int c) {
  const std::string base = fmt::format("{}_{}", qy.prefix, bp(body).ident);
  return ws.loopSlot(base, rows, cols, r, c, fmt::format("{}, body {}", qy.what, body));
}

std::string Emit::kMember(int k, int j) {
  const ConstraintPlan& c = plan.constraints[std::size_t(k)];
  return member("k_" + c.ident, c.rows, j, fmt::format("{}, constraint {}", kK.what, k));
}

std::vector<std::string> Emit::bodyComments(int i, const std::string& stage) const {
  const BodyPlan& b = bp(i);
  const std::string parent = b.parent > 0 ? "'" + escapeComment(bp(b.parent).link) + "'" : "the world";
  return {fmt::format("{}body {} '{}': joint '{}' ({}), parent {}{}", stage.empty() ? "" : stage + " ", i, escapeComment(b.link),
                      escapeComment(b.joint), jointClassName(b.jointClass), parent,
                      b.onSupport ? "" : ", off the support")};
}

V6 Emit::rootAcceleration() const {
  const Vec3 g = model().gravity;
  return {Expr(-g[0]), Expr(-g[1]), Expr(-g[2]), Expr(), Expr(), Expr()};
}

V6 Emit::motionToChild(const Kinematics::Body& b, const V6& m) {
  return actInvMotion(cb(), b.XJ, actInvMotion(cb(), b.XT, m));
}

V6 Emit::forceToParent(const Kinematics::Body& b, const V6& f) { return actForce(cb(), b.XT, actForce(cb(), b.XJ, f)); }

Sym Emit::inertiaToParent(const Kinematics::Body& b, const Sym& M) {
  return congruence(cb(), b.XT, congruence(cb(), b.XJ, M));
}

Rigid Emit::inertiaToParent(const Kinematics::Body& b, const Rigid& r) {
  return rigidToParent(cb(), b.XT, rigidToParent(cb(), b.XJ, r));
}

std::vector<Expr> Emit::constraintRows(int k, const V6& x) {
  const Constraint& c = sys.constraints[std::size_t(k)];
  const V6 y = actInvMotion(cb(), constant(c.placement), x);
  return std::vector<Expr>(y.begin(), y.begin() + c.rows());
}

int axisComponent(const BodyPlan& p) {
  if (p.axis < 0) return -1;
  return p.axis + (p.jointClass <= JointClass::RevoluteAxis ? 3 : 0);
}

}  // namespace proxgen::emit

// constraint_wrenches(q, lambda, w, W), generated (docs/dynamics.md): per
// constraint the wrench its multipliers exert on the robot, in world axes,
// force then torque about the constraint frame's origin. The solvers' sign:
// the constraint force on the robot is -J^T lambda, and the rows are the
// frame's own ([linear; angular] of C in C for a weld, the linear rows for a
// point), so the wrench is -R_C [lambda_lin; lambda_ang] (a point: -R_C lambda,
// no torque), R_C the frame's rotation in the world. Only rotations are
// needed: the support bodies' world rotations root first, from
// constraint_joints(q, w). A constraint on the world moves no body: zeros.
// The generic counterpart: constraintWrenches (algorithms/constraint_kinematics.cpp).
#include <fmt/format.h>

#include "emit/identifiers.hpp"
#include "emit/passes.hpp"

namespace proxgen::emit {

std::string emitConstraintWrenches(Emit& e, const ConstraintJoints& joints) {
  const std::size_t ncons = e.sys.constraints.size();
  Kinematics kin = joints.kin;
  ConstraintOutputs out;
  out.out.assign(6 * ncons, Expr());  // zeros: the constraints on the world stay so
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().cons = &out;
  e.fn.beginHost("wrenches", joints.host);
  e.cb().line("constraint_joints(q, w);", {}, {"q", "w"});
  kin.b[0].oM = constant(SE3::Identity());
  e.fn.beginPass("world", "world rotations of the support bodies, then each constraint's wrench -R_C lambda");
  for (int i : e.plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "world rotation and wrenches:");
    Kinematics::Body& b = kin.b[std::size_t(i)];
    const XSym M = compose(e.cb(), compose(e.cb(), kin.b[std::size_t(e.bp(i).parent)].oM, b.XT), b.XJ);
    for (int k = 0; k < 9; ++k)
      b.oM.R[std::size_t(k)] = e.keepQ(kOR, i, 3, 3, k / 3, k % 3, e.cb().flat(M.R[std::size_t(k)]));
    b.oM.p = zero3();  // positions are not needed (and never printed)
    for (int k : e.bp(i).constraints) {
      const Constraint& c = e.sys.constraints[std::size_t(k)];
      const ConstraintPlan& cp = e.plan.constraints[std::size_t(k)];
      e.cb().comment(fmt::format("constraint '{}' ({}): wrench {}..{}", escapeComment(cp.name), cp.weld ? "6d" : "3d",
                                 6 * k, 6 * k + 5));
      const M3 R = compose(e.cb(), b.oM, constant(c.placement)).R;
      for (int part = 0; part < (cp.weld ? 2 : 1); ++part) {
        V3 l;
        for (int j = 0; j < 3; ++j) l[std::size_t(j)] = -e.cb().input(fmt::format("lambda[{}]", c.row + 3 * part + j));
        const V3 f = rotate(e.cb(), R, l);
        for (int j = 0; j < 3; ++j) {
          const int slot = 6 * k + 3 * part + j;
          out.out[std::size_t(slot)] =
              e.put(e.member("Wc", 6 * int(ncons), slot, "constraint wrenches (world axes)"), f[std::size_t(j)]);
        }
      }
    }
    e.cb().close();
  }
  copyOutput(e, "W", out.out);
  std::string text = e.fn.endHost({"q", "lambda", "w", "W"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

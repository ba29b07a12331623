#include "algorithms/jacobians.hpp"

#include "algorithms/constraints.hpp"
#include "algorithms/kinematics.hpp"

namespace proxgen {

MatX frameJacobian(const System& sys, const Data& d, int body, const SE3& inBody) {
  const Model& m = sys.model;
  MatX J = MatX::Zero(6, m.nv);
  const SE3 cMo = (d.oMi[body] * inBody).inverse();
  for (int i : m.pathToRoot(body)) {
    const Joint& j = m.bodies[i].joint;
    const SE3 cMi = cMo * d.oMi[i];
    for (int k = 0; k < j.nv; ++k) J.col(j.idx_v + k) = cMi.actMotion(d.S[i].col(k));
  }
  return J;
}

void constraintJacobian(const System& sys, Data& d, const VecX& q, const VecX& v) {
  // gamma: the constraint accelerations at qdd = 0 with gravity off.
  forwardKinematics(sys, d, q, v, VecX::Zero(sys.model.nv));
  for (const Constraint& c : sys.constraints) {
    const int r = c.rows();
    const MatX Jc = frameJacobian(sys, d, c.body, c.placement);
    d.J.middleRows(c.row, r) = Jc.topRows(r);
    if (c.type == ConstraintType::Weld6D) d.gamma.segment<6>(c.row) = frameAcceleration(d, c.body, c.placement);
    else d.gamma.segment<3>(c.row) = frameClassicalAcceleration(d, c.body, c.placement);
    d.aStar.segment(c.row, r) = baumgarteTarget(c, framePlacement(d, c.body, c.placement), frameVelocity(d, c.body, c.placement));
  }
}

}  // namespace proxgen

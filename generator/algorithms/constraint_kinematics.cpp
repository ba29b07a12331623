#include "algorithms/constraint_kinematics.hpp"

#include "algorithms/joint_space.hpp"
#include "algorithms/kinematics.hpp"

namespace proxgen {

const VecX& constraintPlacements(const System& sys, Data& d, const VecX& q) {
  forwardKinematics(sys, d, q);
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    const SE3 oMc = framePlacement(d, c.body, c.placement);
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) d.placements[12 * Eigen::Index(k) + 3 * r + col] = oMc.R(r, col);
    d.placements.segment<3>(12 * Eigen::Index(k) + 9) = oMc.p;
  }
  return d.placements;
}

const VecX& constraintWrenches(const System& sys, Data& d, const VecX& q, const VecX& lambda) {
  forwardKinematics(sys, d, q);
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    const Eigen::Index at = 6 * Eigen::Index(k);
    d.wrenches.segment<6>(at).setZero();
    if (c.body == 0) continue;  // on the world: no body of the robot feels it
    const Mat3 R = framePlacement(d, c.body, c.placement).R;
    d.wrenches.segment<3>(at) = -R * lambda.segment<3>(c.row);
    if (c.type == ConstraintType::Weld6D) d.wrenches.segment<3>(at + 3) = -R * lambda.segment<3>(c.row + 3);
  }
  return d.wrenches;
}

const MatX& constraintJacobianRows(const System& sys, Data& d, const VecX& q) {
  forwardKinematics(sys, d, q);
  for (const Constraint& c : sys.constraints) joint_space::fillJacobianRows(sys, d, c);
  return d.J;
}

const VecX& constraintDrift(const System& sys, Data& d, const VecX& q, const VecX& v) {
  forwardKinematics(sys, d, q, v, d.zeroV);  // true accelerations at qdd = 0
  for (const Constraint& c : sys.constraints) {
    if (c.type == ConstraintType::Weld6D) d.gamma.segment<6>(c.row) = frameAcceleration(d, c.body, c.placement);
    else d.gamma.segment<3>(c.row) = frameClassicalAcceleration(d, c.body, c.placement);
  }
  return d.gamma;
}

}  // namespace proxgen

// Frame Jacobians and the stacked constraint Jacobian.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// 6 x nv Jacobian of the frame `inBody` on `body`, in the frame's own
/// coordinates (LOCAL): frame twist = J v. Needs forwardKinematics(q) first.
MatX frameJacobian(const System& sys, const Data& d, int body, const SE3& inBody);

/// The constraint rows J (nc x nv), gamma (nc) and the target aStar (nc) at (q, v):
/// the constraints read J qdd + gamma = aStar on true accelerations (6D: spatial
/// acceleration of C in C; 3D: classical acceleration of C's origin in C).
/// Fills d.J, d.gamma, d.aStar.
void constraintJacobian(const System& sys, Data& d, const VecX& q, const VecX& v);

}  // namespace proxgen

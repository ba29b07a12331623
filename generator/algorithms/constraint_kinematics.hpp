// Where the constraint frames are and how they move (docs/dynamics.md): the
// placements, the stacked Jacobian J and the drift gamma, in the rows the
// solvers hold, so that J qdd + gamma = a* is exactly what constrainedABA,
// proxPV, proxLTL and proxLTLs drive to their target (docs/algorithms.md §2):
//  - 6d weld: the spatial acceleration of frame C in C coordinates, [linear; angular];
//  - 3d point: the classical acceleration of C's origin in C coordinates,
//    a_lin + w_C x v_C.
// Unlike constraintJacobian (jacobians.hpp, the dense reference's), these
// allocate nothing and compute only what is asked.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// d.placements: per constraint (layout order) 12 values, the rotation of its
/// frame in the world (3 x 3, row-major), then the frame origin in the world.
const VecX& constraintPlacements(const System& sys, Data& d, const VecX& q);

/// d.wrenches: per constraint (layout order) 6 values, the wrench its
/// multipliers exert ON THE ROBOT in world axes: the force, then the torque
/// about the constraint frame's origin (the position of constraintPlacements).
/// The solvers' sign: the constraint force on the robot is -J^T lambda, so a
/// weld's wrench is -R [lambda_lin; lambda_ang] and a point's is -R lambda with
/// zero torque (R: the frame's rotation in the world). A constraint on the
/// world (rows of zeros) exerts nothing on the robot: zeros.
const VecX& constraintWrenches(const System& sys, Data& d, const VecX& q, const VecX& lambda);

/// d.J (nc x nv): the rows of each constraint in its own frame C, layout
/// order; frame twist rows = J v (6d: [v_C; w_C], 3d: v_C). Rows of a
/// constraint on the world are zero.
const MatX& constraintJacobianRows(const System& sys, Data& d, const VecX& q);

/// d.gamma (nc): J qdd + gamma is the constraint rows' acceleration, i.e. the
/// rows at qdd = 0 with gravity off (the velocity-product terms, plus w x v
/// for a point).
const VecX& constraintDrift(const System& sys, Data& d, const VecX& q, const VecX& v);

}  // namespace proxgen

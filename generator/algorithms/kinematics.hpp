// Forward kinematics: body placements, velocities and accelerations, and the
// frame quantities built on them. Accelerations here are true ones (no gravity
// shift); the classical acceleration of a frame origin adds w x v.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// liMi, oMi.
void forwardKinematics(const System& sys, Data& d, const VecX& q);
/// + body twists v_i and velocity-product terms c_i.
void forwardKinematics(const System& sys, Data& d, const VecX& q, const VecX& v);
/// + body spatial accelerations a_i (true accelerations, gravity not included).
void forwardKinematics(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd);

/// World placement of a frame placed at `inBody` on `body` (after forwardKinematics).
SE3 framePlacement(const Data& d, int body, const SE3& inBody);
/// Twist of that frame in its own coordinates (after forwardKinematics with v).
Vec6 frameVelocity(const Data& d, int body, const SE3& inBody);
/// Spatial acceleration of that frame in its own coordinates (after forwardKinematics with qdd).
Vec6 frameAcceleration(const Data& d, int body, const SE3& inBody);
/// Classical acceleration of the frame origin, in frame coordinates: a_lin + w x v.
Vec3 frameClassicalAcceleration(const Data& d, int body, const SE3& inBody);

/// log of a placement as a twist [linear; angular] (SE(3) logarithm).
Vec6 log6(const SE3& M);

}  // namespace proxgen

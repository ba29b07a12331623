// Inverse dynamics with constraint forces (docs/dynamics.md): the torques that
// produce a given acceleration while the constraints push with multipliers
// lambda. The sign is the solvers' (docs/algorithms.md §2): the force of the
// constraints on the robot is -J^T lambda, so tau = M qdd + h + J^T lambda.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// d.tau = M(q) qdd + h(q, v) + J(q)^T lambda, gravity from the model. lambda
/// holds the stacked rows in layout order (nc), or is nullptr for no constraint
/// forces (plain RNEA). J^T lambda is applied as body forces K_c^T lambda_c in
/// a second backward sweep, without forming J. No allocation; overwrites the
/// kinematics, d.a and d.f.
const VecX& inverseDynamics(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd,
                            const VecX* lambda);

/// d.tau += J(q)^T lambda, from the placements in d.liMi (any pass that ran
/// forwardKinematics at q). O(n): each constraint's force enters its body and
/// is carried to the root. No allocation; overwrites d.f.
void addConstraintForces(const System& sys, Data& d, const VecX& lambda);

}  // namespace proxgen

// The inverse of the joint-space inertia matrix in O(n^2) without factoring M
// (docs/dynamics.md): ABA run on the nv unit torques at once, with v = 0 and
// gravity off, so column j of M^-1 is the acceleration that tau = e_j gives.
// The structure of that ABA (Carpentier, "Analytical inverse of the
// joint-space inertia matrix", 2018) keeps the cost at O(n^2): a unit torque
// at dof j only loads the bodies from j's body to the root, and only the upper
// triangle is swept, the lower one is its mirror.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// Returns d.Minv = M(q)^-1, full and exactly symmetric. No allocation.
/// Overwrites the ABA quantities (IA, U, Dinv, ...) and d.FA.
const MatX& massMatrixInverse(const System& sys, Data& d, const VecX& q);

}  // namespace proxgen

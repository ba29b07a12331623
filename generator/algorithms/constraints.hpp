// The per-constraint terms the maximal-coordinate recursions use
// (docs/algorithms.md §2): K_i a_i = k_i on the gravity-shifted acceleration
// of the constrained body, with k_i = a_star - drift - K_i X_{i,0} a_g.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// Baumgarte target a_star = -kd * (constraint velocity) - kp * (placement error)
/// for one constraint, given the world placement and own-frame twist of its frame.
VecN baumgarteTarget(const Constraint& c, const SE3& oMc, const Vec6& vC);

/// Fills d.terms (needs d.oMi and d.v).
void computeConstraintTerms(const System& sys, Data& d);

/// Residual ||K a - k|| over all constraints, from the accelerations in d.a.
double constraintResidual(const System& sys, const Data& d);

}  // namespace proxgen

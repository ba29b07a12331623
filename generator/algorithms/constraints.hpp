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

/// The run-time schedule's definition (docs/algorithms.md §4.4): the System of
/// the constraints with active[k] alone, in layout order, rows renumbered.
/// A solver with constraint k inactive answers as a solver of this System
/// (qdd, and lambda on the kept rows; the dropped rows' lambda are 0).
/// active: one flag per constraint of sys.
System activeSubsystem(const System& sys, const std::vector<bool>& active);
/// The rows of sys kept by activeSubsystem(sys, active), in order.
std::vector<int> activeRows(const System& sys, const std::vector<bool>& active);

/// Residual ||K a - k|| over all constraints, from the accelerations in d.a.
double constraintResidual(const System& sys, const Data& d);

}  // namespace proxgen

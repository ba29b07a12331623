// constrainedABA (docs/algorithms.md §4.1): augmented-Lagrangian forward dynamics in
// O(n + m) per solve. The penalty mu K^T K enters the inertia of constrained
// bodies once; iterations 2..K are reduced sweeps over the constraint support.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// K multiplier updates from lambda = 0 (K solves; K = 0 gives the free motion).
/// Results in d.qdd and d.lambda (rows in layout order; the force on the robot
/// is -J^T lambda).
void constrainedAba(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu,
                    int iterations);
/// The same from lambda = *lambda0 (the warm start, docs/algorithms.md §4.3; null: 0):
/// K = 0 gives lambda = lambda0 and the motion under its forces.
void constrainedAbaFrom(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu,
                        int iterations, const VecX* lambda0);

}  // namespace proxgen

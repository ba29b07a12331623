// The derivatives of inverse dynamics in the world frame (Carpentier and
// Mansard, RSS 2018, in proxgen's notation; docs/derivatives.md, section 2b).
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// dtau/dq and dtau/dv of tau = RNEA(q, v, qdd) + J(q)^T lambda at fixed qdd and
/// lambda (lambda nullptr: no constraint forces), the same quantities and the
/// same tangent convention (q (+) dq) as inverseDynamicsDerivatives
/// (algorithms/derivatives.hpp), computed another way: every joint's columns are
/// formed once in the world frame, where a body's motion subspace, inertia and
/// force move with the joints above it only by the cross product with their
/// axes, and each (body, ancestor) pair costs a few six-vector products, where
/// the body-frame tangent sweep carries every column through every transform
/// below it. O(N d) for a tree of depth d, with smaller constants; the reference
/// the world-frame emitter is to be tested against, and an independent check of
/// the body-frame sweep. Overwrites d's kinematics; dtau_dq and dtau_dv are
/// resized to nv x nv.
void inverseDynamicsDerivativesWorld(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd,
                                     const VecX* lambda, MatX& dtau_dq, MatX& dtau_dv);

}  // namespace proxgen

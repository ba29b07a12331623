// The derivatives of inverse dynamics in the world frame (Carpentier and
// Mansard, RSS 2018, in proxgen's notation; docs/derivatives.md, section 2b).
#pragma once

#include "algorithms/data.hpp"
#include "algorithms/derivatives.hpp"

namespace proxgen {

/// What inverseDynamicsDerivatives (algorithms/derivatives.hpp) computes, the
/// same quantities in the same tangent convention (q (+) dq), another way:
/// dd.dtau_dq and dd.dtau_dv of tau = RNEA(q, v, qdd) + J(q)^T lambda at fixed
/// qdd and lambda (lambda nullptr: no constraint forces), and the constraint
/// rows' dd.J, dd.dalpha_*, dd.dastar_*. Every joint's columns are formed once
/// in the world frame, where a body's motion subspace, inertia and force move
/// with the joints above it only by the cross product with their axes, so each
/// (body, ancestor) pair costs a few six-vector products, where the body-frame
/// tangent sweep carries every column through every transform below it: O(N d)
/// for a tree of depth d, with smaller constants. Of the per-body tangents only
/// the constrained bodies' dd.dv_dq, dd.dv_dv, dd.da_dq, dd.da_dv, dd.dg_dq are
/// filled (what constraintRowTangents reads), from the world-frame columns.
/// The reference the world-frame emitter is to be tested against, and an
/// independent check of the body-frame sweep. Overwrites d's kinematics.
void inverseDynamicsDerivativesWorld(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                     const VecX& qdd, const VecX* lambda);

}  // namespace proxgen

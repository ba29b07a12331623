// The Delassus matrix G = J M^-1 J^T of the constraint rows and its damped
// inverse (G + I/mu)^-1 (docs/dynamics.md), rows and columns in layout order.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// d.delassusG = J M^-1 J^T, dense from the pieces: M^-1 by
/// massMatrixInverse, J by constraintJacobianRows, two products. Exactly
/// symmetric. No allocation on the shared cases: Eigen's matrix products block
/// on the stack up to EIGEN_STACK_ALLOCATION_LIMIT (128 kB), which far larger
/// robots would pass.
const MatX& delassus(const System& sys, Data& d, const VecX& q);

/// out = J (M + mu J^T J)^-1 J^T for mu >= 0 (mu = 0: G itself) by a
/// recursion over the constraint support, without forming M, J or a
/// factorisation (docs/dynamics.md, "Delassus recursion"):
///  - the articulated inertias of constrainedABA (penalty mu K^T K on the
///    constrained bodies, docs/algorithms.md §4.1), one backward sweep;
///  - forward, the apparent inverse inertia of every support body, Phi_i =
///    P_i^T X_i Phi_p X_i^T P_i + S_i D_i^-1 S_i^T with P_i = 1 - U_i D_i^-1 S_i^T
///    (the acceleration of body i per unit force on it, all else articulated);
///  - backward, each row's force direction carried to the bodies where rows
///    meet (a 6 x 6 map accumulated along unbranched chains, so a column moves
///    only at constrained and branching bodies), and every entry once, at the
///    nearest common ancestor c of its two rows: K_a T_a^T Phi_c T_b K_b^T.
/// Cost O(n + m^2): a row's column moves once per key body (constrained, or
/// branching on the support) above it, and there are fewer than 2m of those
/// (branch points are fewer than the constrained bodies, which are at most m).
/// out must be nc x nc. No allocation; overwrites the ABA quantities, d.terms,
/// d.KA, d.Phi, d.Tkey, d.keyBelow.
void delassusRecursion(const System& sys, Data& d, const VecX& q, double mu, MatX& out);

/// d.delassusInv = (G + I/mu)^-1, mu > 0, by the Woodbury identity on the
/// penalised recursion: (J M^-1 J^T + I/mu)^-1 = mu I - mu^2 J (M + mu J^T J)^-1 J^T.
/// No factorisation of an m x m matrix: O(n + m^2) like delassusRecursion.
/// Round-off: the two terms cancel down to the answer's size, so the error is
/// about eps mu^2 |J M_mu^-1 J^T| ~ eps mu (absolute), relative eps mu |G| on
/// the stiff rows (docs/dynamics.md).
const MatX& delassusInverse(const System& sys, Data& d, const VecX& q, double mu);

}  // namespace proxgen

// What the joint-space algorithms (proxLTL, proxLTLs) share: the problem in
// joint coordinates (M, h, J, gamma, aStar) filled without allocation, and the
// sparse L^T D L factorisation of a matrix with M's branch-induced sparsity
// (Featherstone 2005; RBDA Table 6.3). `parent` is Data::dofParent: the parent
// dof of each dof, -1 at the root; entry (i, j) can be non-zero only when j is
// i or one of its ancestors, and the factor keeps exactly that pattern.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen::joint_space {

/// d.M (CRBA), d.h (RNEA with qdd = 0), d.terms, and the constraint rows
/// d.J, d.gamma, d.aStar at (q, v), layout order. Overwrites d.qdd, d.tau.
void assemble(const System& sys, Data& d, const VecX& q, const VecX& v);

/// d.J's rows of constraint c (K times its body's Jacobian), from d.oMi.
void fillJacobianRows(const System& sys, Data& d, const Constraint& c);

/// Last dof of a body (-1 for the world): the start of its ancestor chain.
int lastDof(const Model& m, int body);

/// In place: H (lower triangle read) -> D on the diagonal, L strictly below,
/// with H = L^T D L and L unit lower triangular.
void factorLtdl(const std::vector<int>& parent, MatX& H);

/// x <- L^-T x.
void solveLt(const std::vector<int>& parent, const MatX& LD, VecX& x);
/// x <- L^-1 x.
void solveL(const std::vector<int>& parent, const MatX& LD, VecX& x);
/// x <- (L^T D L)^-1 x.
void solve(const std::vector<int>& parent, const MatX& LD, VecX& x);

/// d.rowRes = J qdd + gamma - aStar; returns its norm.
double rowResidual(Data& d);

}  // namespace proxgen::joint_space

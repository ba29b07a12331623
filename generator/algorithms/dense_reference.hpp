// The dense reference (docs/algorithms.md §6): ground truth for tests, built
// from M (CRBA), h (RNEA), J and gamma (frame Jacobians and kinematics) with
// dense Eigen linear algebra, and nothing shared with the recursions.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

struct DenseProblem {
  MatX M, J;
  VecX h, gamma, aStar, tau;
};

/// Assembles M, h, J, gamma, aStar at (q, v) and copies tau.
DenseProblem assembleDense(const System& sys, const VecX& q, const VecX& v, const VecX& tau);

/// K iterations of the proximal/augmented-Lagrangian iteration of section 3 from
/// lambda = 0: lambda+ = (G + I/mu)^-1 (J qdd_free + gamma - aStar + lambda/mu),
/// qdd = qdd_free - M^-1 J^T lambda.
void denseProx(const DenseProblem& p, double mu, int iterations, VecX& qdd, VecX& lambda);

/// The exact constrained answer: lambda = G^+ (J qdd_free + gamma - aStar) with
/// G = J M^-1 J^T by a rank-revealing (complete orthogonal) decomposition, minimum
/// norm, and qdd = qdd_free - M^-1 J^T lambda. For a full-rank J this is the
/// solution of [M J^T; J 0] [qdd; lambda] = [tau - h; aStar - gamma]; for redundant
/// or inconsistent rows it is the least-squares answer the prox iteration's qdd
/// converges to.
void denseExact(const DenseProblem& p, VecX& qdd, VecX& lambda);

}  // namespace proxgen

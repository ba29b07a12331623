// The dense reference (docs/algorithms.md §6). Built only from M (CRBA), h
// (RNEA with qdd = 0) and the frame Jacobians; the linear algebra is plain
// dense Eigen, so it shares no recursion with the solvers it checks.
// Allocates freely: it is ground truth, not a solver.
#include "algorithms/dense_reference.hpp"

#include <Eigen/QR>

#include "algorithms/crba.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/rnea.hpp"

namespace proxgen {
namespace {

// The unconstrained pieces every formula below is written in:
// qdd_free = M^-1 (tau - h), MinvJt = M^-1 J^T, G = J M^-1 J^T (Delassus),
// y = J qdd_free + gamma - aStar (the row accelerations at lambda = 0).
struct DualPieces {
  Eigen::LLT<MatX> Mllt;
  VecX qddFree, y;
  MatX MinvJt, G;
};

DualPieces dualPieces(const DenseProblem& p) {
  DualPieces s;
  s.Mllt.compute(p.M);
  s.qddFree = s.Mllt.solve(p.tau - p.h);
  s.MinvJt = s.Mllt.solve(p.J.transpose());
  s.G = p.J * s.MinvJt;
  s.G = 0.5 * (s.G + s.G.transpose());  // exact symmetry for the factorisations
  s.y = p.J * s.qddFree + p.gamma - p.aStar;
  return s;
}

}  // namespace

DenseProblem assembleDense(const System& sys, const VecX& q, const VecX& v, const VecX& tau) {
  Data d(sys);
  DenseProblem p;
  p.M = crba(sys, d, q);
  p.h = nonLinearEffects(sys, d, q, v);
  constraintJacobian(sys, d, q, v);
  p.J = d.J;
  p.gamma = d.gamma;
  p.aStar = d.aStar;
  p.tau = tau;
  return p;
}

void denseProx(const DenseProblem& p, double mu, int iterations, VecX& qdd, VecX& lambda) {
  const DualPieces s = dualPieces(p);
  const int m = int(p.J.rows());
  lambda = VecX::Zero(m);
  if (m > 0 && iterations > 0) {
    // (G + I/mu) is positive definite for every mu > 0, even when G is singular.
    MatX A = s.G;
    A.diagonal().array() += 1.0 / mu;
    const Eigen::LLT<MatX> llt(A);
    for (int k = 0; k < iterations; ++k) lambda = llt.solve(s.y + lambda / mu);
  }
  qdd = s.qddFree - s.MinvJt * lambda;
}

// Why G^+ y is what the prox iteration converges to, in qdd. Write
// G = V diag(g) V^T. Per eigen-direction the iteration reads
// lambda_j <- (y_j + lambda_j / mu) / (g_j + 1/mu):
//  - g_j > 0: lambda_j -> y_j / g_j geometrically (factor 1 / (1 + mu g_j));
//  - g_j = 0: lambda_j grows by mu y_j per step (without bound when the rows
//    are inconsistent, y_j != 0), but then V_j lies in null(G) = null(J^T)
//    (G = J M^-1 J^T with M > 0), so it never moves qdd = qdd_free - M^-1 J^T lambda.
// Hence qdd^K -> qdd_free - M^-1 J^T G^+ y, with G^+ y the minimum-norm
// least-squares multiplier. That qdd minimises ||J qdd + gamma - aStar|| and,
// among those, ||qdd - qdd_free||_M (Gauss' principle on the consistent part).
// For a consistent full-rank J this is the KKT solution of [M J^T; J 0].
void denseExact(const DenseProblem& p, VecX& qdd, VecX& lambda) {
  const DualPieces s = dualPieces(p);
  if (p.J.rows() == 0) {
    lambda = VecX::Zero(0);
    qdd = s.qddFree;
    return;
  }
  // Rank-revealing: complete orthogonal decomposition, minimum-norm solution.
  const Eigen::CompleteOrthogonalDecomposition<MatX> cod(s.G);
  lambda = cod.solve(s.y);
  qdd = s.qddFree - s.MinvJt * lambda;
}

}  // namespace proxgen

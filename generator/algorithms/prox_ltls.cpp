#include "algorithms/prox_ltls.hpp"

#include "algorithms/joint_space.hpp"

namespace proxgen {
namespace {

using joint_space::lastDof;

// M_mu = M + mu J^T J. Rows of one constraint only touch the dofs on its
// body's ancestor chain, so each product J_k^T J_l lands on a pair of dofs
// on one path: inside M's branch-induced pattern.
void penalisedInertia(const System& sys, Data& d, double mu) {
  const std::vector<int>& parent = d.dofParent;
  d.Mmu = d.M;
  for (const Constraint& c : sys.constraints)
    for (int k = lastDof(sys.model, c.body); k >= 0; k = parent[k])
      for (int l = k; l >= 0; l = parent[l]) {
        const double jj = mu * d.J.col(k).segment(c.row, c.rows()).dot(d.J.col(l).segment(c.row, c.rows()));
        d.Mmu(k, l) += jj;
        if (l != k) d.Mmu(l, k) += jj;
      }
}

}  // namespace

void proxLtls(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations) {
  const std::vector<int>& parent = d.dofParent;
  joint_space::assemble(sys, d, q, v);
  d.lambda.setZero();
  if (iterations == 0 || sys.nc == 0) {
    // The free motion: no penalty, M qdd = tau - h.
    d.LD = d.M;
    joint_space::factorLtdl(parent, d.LD);
    d.qdd = tau - d.h;
    joint_space::solve(parent, d.LD, d.qdd);
    d.iterationsDone = iterations;
    d.residual = joint_space::rowResidual(d);
    return;
  }
  penalisedInertia(sys, d, mu);
  d.LD = d.Mmu;
  joint_space::factorLtdl(parent, d.LD);
  // Stationarity of the augmented Lagrangian (Gauss' principle + lambda^T r + mu/2 |r|^2,
  // r = J qdd + gamma - aStar): M_mu qdd = tau - h - J^T (lambda + mu (gamma - aStar)).
  // Each iteration: one sparse solve, then lambda += mu r. K updates = K solves,
  // and the last solve's qdd is qdd^K (docs/algorithms.md §3).
  for (int k = 0; k < iterations; ++k) {
    d.rhs = d.lambda + mu * (d.gamma - d.aStar);
    d.qdd = tau - d.h;
    d.qdd.noalias() -= d.J.transpose() * d.rhs;
    joint_space::solve(parent, d.LD, d.qdd);
    d.residual = joint_space::rowResidual(d);  // fills d.rowRes = r
    d.lambda += mu * d.rowRes;
  }
  d.iterationsDone = iterations;
}

}  // namespace proxgen

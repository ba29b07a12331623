#include "algorithms/prox_pv.hpp"

#include "algorithms/aba.hpp"
#include "algorithms/constraints.hpp"

namespace proxgen {

void proxPv(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations) {
  proxPvFrom(sys, d, q, v, tau, mu, iterations, nullptr);
}

void proxPvFrom(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations,
                const VecX* lambda0) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  aba_steps::initialise(sys, d, q, v);
  computeConstraintTerms(sys, d);

  // docs/algorithms.md §4.2 with lA_i and LA_i kept in place: subtree i's rows are
  // the block [s_i, s_i + m_(i)) of the tree order, so "lA_p[rows of i] = lA_i + ..."
  // and "LA_p[block of i] = LA_i + ..." add into that block of y_free and G,
  // and nothing is copied from child to parent.
  d.yfree.setZero();
  d.G.setZero();

  // Each constrained body starts its rows: KA = K^T, lA = -k.
  for (int i = 0; i < N; ++i) {
    int col = 0;
    for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
      const Constraint& c = sys.constraints[k];
      if (c.body != i) continue;
      d.KA[i].middleCols(col, c.rows()) = d.terms[k].K.transpose();
      d.yfree.segment(d.subtreeStart[i] + col, c.rows()) = -d.terms[k].k;
      col += c.rows();
    }
  }

  // Backward: plain ABA elimination, and the subtree rows handed to the parent.
  for (int i = N - 1; i >= 1; --i) {
    aba_steps::eliminate(sys, d, i, tau);
    const int mi = int(d.subtreeRows[i].size());
    if (mi == 0) continue;
    const int p = m.bodies[i].parent;
    const int si = d.subtreeStart[i];
    const int offset = si - d.subtreeStart[p];  // subtree i's columns in KA_p
    d.KS[i].noalias() = d.S[i].transpose() * d.KA[i];
    const Vec6 aFree = d.c[i] + d.S[i] * (d.Dinv[i] * (d.u[i] - d.U[i].transpose() * d.c[i]));
    d.yfree.segment(si, mi).noalias() += d.KA[i].transpose() * aFree;
    d.DinvKS[i].noalias() = d.Dinv[i] * d.KS[i];
    auto LAi = d.G.block(si, si, mi, mi);  // only its lower triangle is kept: the LLT reads no more
    if (m.bodies[i].joint.nv == 1) {  // rank-one updates (outer products, not matrix products)
      LAi.selfadjointView<Eigen::Lower>().rankUpdate(d.KS[i].row(0).transpose(), d.Dinv[i](0, 0));
      d.KA[i].noalias() -= d.U[i].col(0) * d.DinvKS[i].row(0);
    } else {
      LAi.noalias() += d.KS[i].transpose() * d.DinvKS[i];
      d.KA[i].noalias() -= d.U[i] * d.DinvKS[i];
    }
    // KA_i is not needed after this: it now holds KA_i - U D^-1 KS, the rows seen through the joint.
    for (int col = 0; col < mi; ++col) d.KA[p].col(offset + col) = d.liMi[i].actForce(d.KA[i].col(col));
  }

  // Root: y_free = lA_0 + KA_0^T a_0 ; (G + I/mu) lambda+ = y_free + lambda/mu,
  // G = LA_0 (lower triangle).
  aba_steps::setRootAcceleration(sys, d);
  const std::vector<int>& rows = d.subtreeRows[0];
  const int nc = sys.nc;
  d.yfree.noalias() += d.KA[0].transpose() * d.a[0];
  d.G.diagonal().array() += 1.0 / mu;
  d.llt.compute(d.G);
  d.lambdaTree.setZero();
  if (lambda0)
    for (int r = 0; r < nc; ++r) d.lambdaTree[r] = (*lambda0)[rows[r]];  // the warm start, in tree order
  for (int k = 0; k < iterations && nc > 0; ++k) {
    d.lambdaTree = d.yfree + d.lambdaTree / mu;
    d.llt.solveInPlace(d.lambdaTree);
  }
  for (int r = 0; r < nc; ++r) d.lambda[rows[r]] = d.lambdaTree[r];

  // Forward: qdd_i = D^-1 (u_i - KS_i lambda_(i) - U^T a'_i).
  for (int i = 1; i < N; ++i) {
    const int mi = int(d.subtreeRows[i].size());
    if (mi > 0) {
      const VecN u0 = d.u[i];
      d.u[i].noalias() -= d.KS[i] * d.lambdaTree.segment(d.subtreeStart[i], mi);  // lambda_(i)
      aba_steps::accelerate(sys, d, i);
      d.u[i] = u0;
    } else {
      aba_steps::accelerate(sys, d, i);
    }
  }
  d.iterationsDone = iterations;
  d.residual = constraintResidual(sys, d);
}

}  // namespace proxgen

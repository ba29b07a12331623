// Notation (docs/algorithms.md §1, §4): body i with dofs [s_i, s_i + n_i),
// subtree dofs [s_i, e_i) (depth-first order makes them contiguous).
// Backward, bodies N-1 .. 1, column j of F_i is the bias force pA_i of the
// ABA with tau = e_j (zero unless j is in i's subtree):
//   row i of Minv, columns [s_i, e_i): D_i^-1 u_i with u_i = e_j - S_i^T F_i[:, j]
//   F_i[:, j] += U_i D_i^-1 u_i              (pa_i = pA_i + U_i D_i^-1 u_i; c_i = 0)
//   F_p[:, j] += X_i^T F_i[:, j]
// Forward, bodies 1 .. N-1, for the columns j >= s_i (the upper triangle), with
// A_i[:, j] the acceleration of body i under tau = e_j (the world's is 0):
//   a'_i = X_i A_p[:, j] ; Minv(i, j) = D_i^-1 u_i - D_i^-1 U_i^T a'_i ;
//   A_i[:, j] = a'_i + S_i Minv(i, j).
// Columns j >= e_i belong to later branches: u_i = 0 there (zeroed first).
// F_i and A_i share the buffer d.FA[i]: body i's forces are last read by its own
// backward step, before the forward pass writes its accelerations.
#include "algorithms/mass_matrix_inverse.hpp"

#include "algorithms/aba.hpp"

namespace proxgen {

const MatX& massMatrixInverse(const System& sys, Data& d, const VecX& q) {
  const Model& m = sys.model;
  const int N = m.numBodies(), nv = m.nv;
  aba_steps::initialise(sys, d, q, d.zeroV);  // IA = I, v = c = pA = 0
  d.Minv.setZero();
  for (int i = 1; i < N; ++i) d.FA[i].setZero();

  for (int i = N - 1; i >= 1; --i) {
    aba_steps::eliminate(sys, d, i, d.zeroV);  // U_i, D_i^-1; IA_p += X^T Ia X
    const Joint& ji = m.bodies[i].joint;
    const int s = ji.idx_v, n = ji.nv, e = d.subtreeDofEnd[i];
    MatX& F = d.FA[i];
    d.Minv.block(s, s, n, n) = d.Dinv[i];  // u_i = e_j on the own dofs
    for (int j = s + n; j < e; ++j) d.Minv.block(s, j, n, 1).noalias() = -d.Dinv[i] * (d.S[i].transpose() * F.col(j));
    for (int j = s; j < e; ++j) F.col(j).noalias() += d.U[i] * d.Minv.block(s, j, n, 1);
    const int p = m.bodies[i].parent;
    if (p > 0)
      for (int j = s; j < e; ++j) d.FA[p].col(j) += d.liMi[i].actForce(F.col(j));
  }

  for (int i = 1; i < N; ++i) {
    const Joint& ji = m.bodies[i].joint;
    const int s = ji.idx_v, n = ji.nv, p = m.bodies[i].parent;
    MatX& A = d.FA[i];
    for (int j = s; j < nv; ++j) {
      Vec6 a = Vec6::Zero();
      if (p > 0) {
        a = d.liMi[i].actInvMotion(d.FA[p].col(j));
        d.Minv.block(s, j, n, 1).noalias() -= d.Dinv[i] * (d.U[i].transpose() * a);
      }
      A.col(j).noalias() = a + d.S[i] * d.Minv.block(s, j, n, 1);
    }
  }
  // The lower triangle is the mirror of the upper one (M^-1 is symmetric); the
  // diagonal blocks of a multi-dof joint are D^-1 - ..., mirrored too.
  for (int c = 0; c < nv; ++c)
    for (int r = c + 1; r < nv; ++r) d.Minv(r, c) = d.Minv(c, r);
  return d.Minv;
}

}  // namespace proxgen

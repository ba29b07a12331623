#include "algorithms/delassus.hpp"

#include "algorithms/aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/constraints.hpp"
#include "algorithms/mass_matrix_inverse.hpp"

namespace proxgen {
namespace {

// P_i = 1 - U_i D_i^-1 S_i^T: what joint i lets through of a force on body i.
Mat6 transmission(const Data& d, int i) {
  Mat6 P = Mat6::Identity();
  P.noalias() -= d.U[i] * (d.Dinv[i] * d.S[i].transpose());
  return P;
}

// Exact symmetry from the upper triangle's mirror average.
void symmetrise(MatX& A) {
  for (Eigen::Index c = 0; c < A.cols(); ++c)
    for (Eigen::Index r = c + 1; r < A.rows(); ++r) A(r, c) = A(c, r) = 0.5 * (A(r, c) + A(c, r));
}

}  // namespace

const MatX& delassus(const System& sys, Data& d, const VecX& q) {
  massMatrixInverse(sys, d, q);
  constraintJacobianRows(sys, d, q);
  d.JMinvLib.noalias() = d.J * d.Minv;
  d.delassusG.noalias() = d.JMinvLib * d.J.transpose();
  symmetrise(d.delassusG);
  return d.delassusG;
}

void delassusRecursion(const System& sys, Data& d, const VecX& q, double mu, MatX& out) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  out.setZero();  // pairs meeting only at the world, and rows on the world, stay 0
  if (sys.nc == 0) return;
  aba_steps::initialise(sys, d, q, d.zeroV);
  computeConstraintTerms(sys, d);  // K (k is not used)
  if (mu > 0)
    for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
      const int i = sys.constraints[k].body;
      if (i > 0) d.IA[i].noalias() += mu * d.terms[k].K.transpose() * d.terms[k].K;
    }
  for (int i = N - 1; i >= 1; --i) aba_steps::eliminate(sys, d, i, d.zeroV);

  // Forward: apparent inverse inertias along the support (the world does not move).
  for (int i : d.support) {
    d.Phi[i].noalias() = d.S[i] * (d.Dinv[i] * d.S[i].transpose());
    const int p = m.bodies[i].parent;
    if (p == 0) continue;
    // B = X_i^T P_i carries a force on i to p; a_i = B^T a_p + S_i D_i^-1 S_i^T f.
    const Mat6 B = d.liMi[i].motionMatrixInv().transpose() * transmission(d, i);
    d.Phi[i].noalias() += B.transpose() * d.Phi[p] * B;
  }

  // Backward over the support, leaves first.
  for (auto it = d.support.rbegin(); it != d.support.rend(); ++it) {
    const int i = *it;
    // Own rows: the subtree's less the children's (O(children), not O(m) per body).
    int own = int(d.subtreeRows[i].size()), supportChildren = 0, onlyChild = -1;
    for (int ch : m.bodies[i].children) {
      own -= int(d.subtreeRows[ch].size());
      if (d.onSupport[ch]) ++supportChildren, onlyChild = ch;
    }
    if (own == 0 && supportChildren == 1) {  // an unbranched link of a chain: accumulate the map only
      const Mat6 T = d.liMi[onlyChild].motionMatrixInv().transpose() * transmission(d, onlyChild);
      d.Tkey[i].noalias() = T * d.Tkey[onlyChild];
      d.keyBelow[i] = d.keyBelow[onlyChild];
      continue;
    }
    d.keyBelow[i] = i;
    d.Tkey[i].setIdentity();
    MatX& KA = d.KA[i];
    // Columns: own rows (layout order), then each child's subtree rows (data.hpp).
    int col = 0;
    for (std::size_t k = 0; k < sys.constraints.size(); ++k)
      if (sys.constraints[k].body == i) {
        KA.middleCols(col, sys.constraints[k].rows()) = d.terms[k].K.transpose();
        col += sys.constraints[k].rows();
      }
    for (int ch : m.bodies[i].children) {
      if (!d.onSupport[ch]) continue;
      const int offset = d.subtreeStart[ch] - d.subtreeStart[i], mc = int(d.subtreeRows[ch].size());
      const Mat6 T = d.liMi[ch].motionMatrixInv().transpose() * transmission(d, ch) * d.Tkey[ch];
      KA.middleCols(offset, mc).noalias() = T * d.KA[d.keyBelow[ch]];
    }
    // Entries whose rows meet here: both in the own group, or in different groups.
    const std::vector<int>& rows = d.subtreeRows[i];
    const int mi = int(rows.size());
    auto fill = [&](int from, int to, bool ownGroup) {
      for (int b = from; b < to; ++b) {
        const Vec6 w = d.Phi[i] * KA.col(b);
        if (ownGroup) {
          for (int a = 0; a < mi; ++a) out(rows[a], rows[b]) = KA.col(a).dot(w);
        } else {
          for (int a = 0; a < from; ++a) out(rows[a], rows[b]) = KA.col(a).dot(w);
          for (int a = to; a < mi; ++a) out(rows[a], rows[b]) = KA.col(a).dot(w);
        }
      }
    };
    fill(0, own, true);
    for (int ch : m.bodies[i].children)
      if (d.onSupport[ch]) {
        const int offset = d.subtreeStart[ch] - d.subtreeStart[i];
        fill(offset, offset + int(d.subtreeRows[ch].size()), false);
      }
  }
  symmetrise(out);
}

const MatX& delassusInverse(const System& sys, Data& d, const VecX& q, double mu) {
  delassusRecursion(sys, d, q, mu, d.delassusInv);
  d.delassusInv *= -mu * mu;
  d.delassusInv.diagonal().array() += mu;
  return d.delassusInv;
}

}  // namespace proxgen

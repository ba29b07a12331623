#include "algorithms/joint_space.hpp"

#include "algorithms/constraints.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/rnea.hpp"

namespace proxgen::joint_space {

int lastDof(const Model& m, int body) {
  return body > 0 ? m.bodies[body].joint.idx_v + m.bodies[body].joint.nv - 1 : -1;
}

// Rows of constraint c: K times the body Jacobian of its body, i.e. each
// ancestor joint's motion subspace seen in the constraint frame C.
void fillJacobianRows(const System& sys, Data& d, const Constraint& c) {
  const Model& m = sys.model;
  const int r = c.rows();
  d.J.middleRows(c.row, r).setZero();
  const SE3 oMc = d.oMi[c.body] * c.placement;
  for (int i = c.body; i > 0; i = m.bodies[i].parent) {
    const Joint& j = m.bodies[i].joint;
    for (int k = 0; k < j.nv; ++k) {
      const Vec6 col = oMc.actInvMotion(d.oMi[i].actMotion(d.S[i].col(k)));
      d.J.block(c.row, j.idx_v + k, r, 1) = col.head(r);
    }
  }
}

void assemble(const System& sys, Data& d, const VecX& q, const VecX& v) {
  crba(sys, d, q);
  // h = RNEA(q, v, 0). RNEA leaves in d.a the gravity-shifted bias
  // accelerations a0_i = a_i(qdd = 0) - X_{i,0} a_g (docs/algorithms.md §1).
  d.qdd.setZero();
  d.h = rnea(sys, d, q, v, d.qdd);
  computeConstraintTerms(sys, d);
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    const int r = c.rows();
    const SE3 oMc = d.oMi[c.body] * c.placement;
    d.aStar.segment(c.row, r) = baumgarteTarget(c, oMc, c.placement.actInvMotion(d.v[c.body]));
    // K a0 - k = gamma - aStar: k already holds aStar, the drift and the gravity shift.
    d.gamma.segment(c.row, r) = d.terms[k].K * d.a[c.body] - d.terms[k].k + d.aStar.segment(c.row, r);
    fillJacobianRows(sys, d, c);
  }
}

void factorLtdl(const std::vector<int>& parent, MatX& H) {
  for (int k = int(parent.size()) - 1; k >= 0; --k) {
    const double invD = 1.0 / H(k, k);  // one division per dof, not one per ancestor
    for (int i = parent[k]; i >= 0; i = parent[i]) {
      const double a = H(k, i) * invD;
      for (int j = i; j >= 0; j = parent[j]) H(i, j) -= a * H(k, j);
      H(k, i) = a;
    }
  }
}

void solveLt(const std::vector<int>& parent, const MatX& LD, VecX& x) {
  for (int i = int(parent.size()) - 1; i >= 0; --i)
    for (int j = parent[i]; j >= 0; j = parent[j]) x[j] -= LD(i, j) * x[i];
}

void solveL(const std::vector<int>& parent, const MatX& LD, VecX& x) {
  for (int i = 0; i < int(parent.size()); ++i)
    for (int j = parent[i]; j >= 0; j = parent[j]) x[i] -= LD(i, j) * x[j];
}

void solve(const std::vector<int>& parent, const MatX& LD, VecX& x) {
  solveLt(parent, LD, x);
  x.array() /= LD.diagonal().array();
  solveL(parent, LD, x);
}

double rowResidual(Data& d) {
  d.rowRes.noalias() = d.J * d.qdd;
  d.rowRes += d.gamma - d.aStar;
  return d.rowRes.norm();
}

}  // namespace proxgen::joint_space

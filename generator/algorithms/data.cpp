#include "algorithms/data.hpp"

namespace proxgen {

Data::Data(const System& sys) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  I.resize(N, Mat6::Zero());
  S.resize(N);
  for (int i = 1; i < N; ++i) {
    I[i] = m.bodies[i].inertia.matrix();
    S[i] = m.motionSubspace(i);
  }
  liMi.resize(N);
  oMi.resize(N);
  v.assign(N, Vec6::Zero());
  a.assign(N, Vec6::Zero());
  c.assign(N, Vec6::Zero());
  IA.assign(N, Mat6::Zero());
  pA.assign(N, Vec6::Zero());
  dp.assign(N, Vec6::Zero());
  U.resize(N);
  Dinv.resize(N);
  u.resize(N);
  for (int i = 1; i < N; ++i) {
    const int n = m.bodies[i].joint.nv;
    U[i] = Mat6N::Zero(6, n);
    Dinv[i] = MatNN::Zero(n, n);
    u[i] = VecN::Zero(n);
  }

  terms.resize(sys.constraints.size());
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const int r = sys.constraints[k].rows();
    terms[k].K = MatN6::Zero(r, 6);
    terms[k].k = VecN::Zero(r);
  }
  // The tree facts the generated solvers' plan reads too (model/tree.cpp).
  const ConstraintTree tree = constraintTree(sys);
  support = tree.support;
  onSupport = tree.onSupport;
  lambda = VecX::Zero(sys.nc);
  dlambda = VecX::Zero(sys.nc);
  subtreeRows = tree.subtreeRows;
  subtreeStart = tree.subtreeStart;
  KA.resize(N);
  KS.resize(N);
  DinvKS.resize(N);
  for (int i = 0; i < N; ++i) {
    const int mi = int(subtreeRows[i].size());
    KA[i] = MatX::Zero(6, mi);
    KS[i] = MatX::Zero(i > 0 ? m.bodies[i].joint.nv : 0, mi);
    DinvKS[i] = KS[i];
  }
  G = MatX::Zero(sys.nc, sys.nc);
  // Sizes the factor once. Not `llt = LLT<MatX>(nc)`: that constructor leaves
  // the status unset and the assignment reads it (UBSan, scripts/sanitize.sh).
  llt.compute(MatX::Identity(sys.nc, sys.nc));
  yfree = VecX::Zero(sys.nc);
  lambdaTree = VecX::Zero(sys.nc);
  rhs = VecX::Zero(sys.nc);

  qdd = VecX::Zero(m.nv);
  tau = VecX::Zero(m.nv);
  h = VecX::Zero(m.nv);
  M = MatX::Zero(m.nv, m.nv);
  J = MatX::Zero(sys.nc, m.nv);
  gamma = VecX::Zero(sys.nc);
  aStar = VecX::Zero(sys.nc);
  Ic.assign(N, Mat6::Zero());
  f.assign(N, Vec6::Zero());
  dofParent.assign(m.nv, -1);
  for (int i = 1; i < N; ++i) {
    const Joint& j = m.bodies[i].joint;
    const int p = m.bodies[i].parent;
    const int parentLastDof = p > 0 ? m.bodies[p].joint.idx_v + m.bodies[p].joint.nv - 1 : -1;
    for (int k = 0; k < j.nv; ++k) dofParent[j.idx_v + k] = k == 0 ? parentLastDof : j.idx_v + k - 1;
  }
  Mmu = MatX::Zero(m.nv, m.nv);
  JMinv = MatX::Zero(sys.nc, m.nv);
  work = VecX::Zero(std::max(m.nv, sys.nc));
  LD = MatX::Zero(m.nv, m.nv);
  jsB = VecX::Zero(m.nv);
  rowRes = VecX::Zero(sys.nc);

  zeroV = VecX::Zero(m.nv);
  placements = VecX::Zero(12 * Eigen::Index(sys.constraints.size()));
  wrenches = VecX::Zero(6 * Eigen::Index(sys.constraints.size()));
  Minv = MatX::Zero(m.nv, m.nv);
  FA.assign(N, MatX::Zero(6, m.nv));
  subtreeDofEnd.assign(N, 0);
  for (int i = N - 1; i >= 1; --i) {
    subtreeDofEnd[i] = std::max(subtreeDofEnd[i], m.bodies[i].joint.idx_v + m.bodies[i].joint.nv);
    const int p = m.bodies[i].parent;
    if (p > 0) subtreeDofEnd[p] = std::max(subtreeDofEnd[p], subtreeDofEnd[i]);
  }
  Phi.assign(N, Mat6::Zero());
  Tkey.assign(N, Mat6::Identity());
  keyBelow.assign(N, -1);
  delassusG = MatX::Zero(sys.nc, sys.nc);
  delassusInv = MatX::Zero(sys.nc, sys.nc);
  JMinvLib = MatX::Zero(sys.nc, m.nv);
}

}  // namespace proxgen

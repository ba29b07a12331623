#include "algorithms/rnea_derivatives_world.hpp"

#include "algorithms/kinematics.hpp"

namespace proxgen {
namespace {

// The cross products as matrices: (v x) m = crossMotion(v, m), (v x*) f =
// crossForce(v, f) = -(v x)^T f, and H(h) u = crossForce(u, h), the force cross
// product read as linear in its motion argument.
Mat6 motionCross(const Vec6& v) {
  Mat6 X = Mat6::Zero();
  X.topLeftCorner<3, 3>() = X.bottomRightCorner<3, 3>() = skew(ang(v));
  X.topRightCorner<3, 3>() = skew(lin(v));
  return X;
}
Mat6 forceCross(const Vec6& v) { return -motionCross(v).transpose(); }
Mat6 forceCrossOf(const Vec6& h) {
  Mat6 H = Mat6::Zero();
  H.topRightCorner<3, 3>() = H.bottomLeftCorner<3, 3>() = -skew(lin(h));
  H.bottomRightCorner<3, 3>() = -skew(ang(h));
  return H;
}

}  // namespace

// World-frame quantities carry a leading o: oS_i, ov_i, oa_i (gravity-shifted,
// oa_0 = -a_g), oI_i, of_i = oI_i oa_i + ov_i x* oI_i ov_i (+ the constraint
// forces, fixed in body coordinates). Moving joint j by dq along its world axis
// s (q (+) dq) moves everything attached to its subtree by the twist s dq:
// oS_k -> oS_k + s x oS_k, oI_k -> oI_k + s x* oI_k - oI_k s x, and for the
// states, with l the parent of j,
//   d ov_i = s x ov_i - u,                       u = s x ov_l,
//   d oa_i = s x oa_i + c - u x ov_i,            c = -s x oa_l + u x ov_l,
// so d of_i = s x* of_i + oI_i c - B_i u, with the body's
//   B_i = -oI_i (ov_i x) + H(oI_i ov_i) + (ov_i x*) oI_i.
// Along qd_j: d ov_i = s, d oa_i = s x ov_i + w (w = -s x (ov_l + ov_j)), so
// d of_i = oI_i w + B_i s. With the subtree sums Ic, Bc, F (composite inertia,
// composite B, subtree force), tau_k = oS_k^T F_k gives, for k in j's subtree
// (the s x terms of oS_k and F_k cancel: (s x m)^T f + m^T (s x* f) = 0),
//   d tau_k / dq_j = oS_k^T (Ic_k c - Bc_k u),   d tau_k / dqd_j = oS_k^T (Ic_k w + Bc_k s),
// and for k a strict ancestor of j (oS_k fixed; F_k moves by j's subtree's force)
//   d tau_k / dq_j = oS_k^T (s x* F_j + Ic_j c - Bc_j u),   d tau_k / dqd_j = oS_k^T (Ic_j w + Bc_j s).
// A constrained body b's own tangents, in its coordinates (oX_b moves by s too,
// so d (oX_b^-1 m) = oX_b^-1 (dm - s x m)): along q_j, dv_b = oX_b^-1 (-u),
// da_b = oX_b^-1 (c - u x ov_b), dg_b = oX_b^-1 (-s x oa_0); along qd_j,
// dv_b = oX_b^-1 s, da_b = oX_b^-1 (s x ov_b + w).
void inverseDynamicsDerivativesWorld(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                     const VecX& qdd, const VecX* lambda) {
  const Model& m = sys.model;
  const int N = m.numBodies(), nv = m.nv;
  forwardKinematics(sys, d, q, v);  // liMi, oMi, v_i, c_i
  std::vector<Vec6> a(N), ov(N, Vec6::Zero()), oa(N), F(N, Vec6::Zero());
  std::vector<Mat6> Ic(N, Mat6::Zero()), Bc(N, Mat6::Zero());
  std::vector<MatX> oS(N);
  a[0] = oa[0] = stack(-m.gravity, Vec3::Zero());
  for (int i = 1; i < N; ++i) {  // root first: the primal RNEA, then its world-frame picture
    const Joint& j = m.bodies[i].joint;
    const int p = m.bodies[i].parent;
    const SE3& oM = d.oMi[i];
    a[i] = d.liMi[i].actInvMotion(a[p]) + d.S[i] * qdd.segment(j.idx_v, j.nv) + d.c[i];
    ov[i] = oM.actMotion(d.v[i]);
    oa[i] = oM.actMotion(a[i]);
    oS[i].resize(6, j.nv);
    for (int k = 0; k < j.nv; ++k) oS[i].col(k) = oM.actMotion(d.S[i].col(k));
    const Mat6 oI = oM.actInertia(d.I[i]);
    const Vec6 h = oI * ov[i];
    Ic[i] = oI;
    Bc[i] = -oI * motionCross(ov[i]) + forceCrossOf(h) + forceCross(ov[i]) * oI;
    F[i] = oI * oa[i] + crossForce(ov[i], h);
  }
  if (lambda != nullptr)  // K_c^T lambda_c, constant in body coordinates: attached to the body
    for (const Constraint& c : sys.constraints)
      if (c.body > 0)
        F[c.body] += d.oMi[c.body].actForce(c.placement.motionMatrixInv().topRows(c.rows()).transpose() *
                                            lambda->segment(c.row, c.rows()));
  for (int i = N - 1; i >= 1; --i) {  // leaves first: the subtree sums
    const int p = m.bodies[i].parent;
    if (p == 0) continue;
    Ic[p] += Ic[i];
    Bc[p] += Bc[i];
    F[p] += F[i];
  }
  // Per joint column: u, c, w and j's subtree's force derivatives; per body
  // column: Ic_k oS_k and Bc_k^T oS_k, the left factors of the subtree case.
  std::vector<MatX> U(N), C(N), W(N), Pq(N), Pv(N), IS(N), BS(N);
  for (int j = 1; j < N; ++j) {
    const int l = m.bodies[j].parent, n = int(oS[j].cols());
    for (MatX* x : {&U[j], &C[j], &W[j], &Pq[j], &Pv[j]}) x->resize(6, n);
    for (int k = 0; k < n; ++k) {
      const Vec6 s = oS[j].col(k);
      const Vec6 u = crossMotion(s, ov[l]);
      U[j].col(k) = u;
      C[j].col(k) = -crossMotion(s, oa[l]) + crossMotion(u, ov[l]);
      W[j].col(k) = -crossMotion(s, ov[l] + ov[j]);
      Pq[j].col(k) = crossForce(s, F[j]) + Ic[j] * C[j].col(k) - Bc[j] * u;
      Pv[j].col(k) = Ic[j] * W[j].col(k) + Bc[j] * s;
    }
    IS[j] = Ic[j] * oS[j];
    BS[j] = Bc[j].transpose() * oS[j];
  }
  MatX& dtau_dq = dd.dtau_dq;
  MatX& dtau_dv = dd.dtau_dv;
  dtau_dq.setZero(nv, nv);
  dtau_dv.setZero(nv, nv);
  for (int k = 1; k < N; ++k) {  // every (body k, ancestor-or-self j) pair once
    const int rk = m.bodies[k].joint.idx_v, nk = int(oS[k].cols());
    for (int j = k; j != 0; j = m.bodies[j].parent) {
      const int cj = m.bodies[j].joint.idx_v, nj = int(oS[j].cols());
      // rows of k, columns of j: k is in j's subtree
      dtau_dq.block(rk, cj, nk, nj) = IS[k].transpose() * C[j] - BS[k].transpose() * U[j];
      dtau_dv.block(rk, cj, nk, nj) = IS[k].transpose() * W[j] + BS[k].transpose() * oS[j];
      if (j == k) continue;
      // rows of j, columns of k: j is a strict ancestor of k
      dtau_dq.block(cj, rk, nj, nk) = oS[j].transpose() * Pq[k];
      dtau_dv.block(cj, rk, nj, nk) = oS[j].transpose() * Pv[k];
    }
  }
  for (const Constraint& c : sys.constraints) {  // the constrained bodies' tangents, then the rows
    const int b = c.body;
    if (b == 0) continue;
    for (MatX* t : {&dd.dv_dq[b], &dd.dv_dv[b], &dd.da_dq[b], &dd.da_dv[b], &dd.dg_dq[b]}) t->setZero();
    const SE3& oM = d.oMi[b];
    for (int j = b; j != 0; j = m.bodies[j].parent)
      for (int k = 0; k < int(oS[j].cols()); ++k) {
        const int col = m.bodies[j].joint.idx_v + k;
        const Vec6 s = oS[j].col(k), u = U[j].col(k);
        dd.dv_dq[b].col(col) = oM.actInvMotion(-u);
        dd.dv_dv[b].col(col) = oM.actInvMotion(s);
        dd.da_dq[b].col(col) = oM.actInvMotion(C[j].col(k) - crossMotion(u, ov[b]));
        dd.da_dv[b].col(col) = oM.actInvMotion(crossMotion(s, ov[b]) + W[j].col(k));
        dd.dg_dq[b].col(col) = oM.actInvMotion(-crossMotion(s, oa[0]));
      }
  }
  constraintRowTangents(sys, d, dd);
}

}  // namespace proxgen

#include "algorithms/derivatives.hpp"

#include "algorithms/aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/prox_pv.hpp"

namespace proxgen {

DerivativeData::DerivativeData(const System& sys) {
  const int N = sys.model.numBodies(), nv = sys.model.nv, nc = sys.nc;
  a.assign(N, Vec6::Zero());
  g.assign(N, Vec6::Zero());
  f.assign(N, Vec6::Zero());
  for (std::vector<MatX>* t : {&dv_dq, &dv_dv, &da_dq, &da_dv, &dg_dq, &df_dq, &df_dv}) t->assign(N, MatX::Zero(6, nv));
  dtau_dq = dtau_dv = MatX::Zero(nv, nv);
  dalpha_dq = dalpha_dv = dastar_dq = dastar_dv = J = MatX::Zero(nc, nv);
  qdd = VecX::Zero(nv);
  lambda = VecX::Zero(nc);
  dqdd_dq = dqdd_dv = dqdd_dtau = MatX::Zero(nv, nv);
  dlambda_dq = dlambda_dv = dlambda_dtau = MatX::Zero(nc, nv);
  lltM.compute(MatX::Identity(nv, nv));  // sizes the factors once (see Data::llt)
  lltG.compute(MatX::Identity(nc, nc));
  MinvJt = MatX::Zero(nv, nc);
  G = MatX::Zero(nc, nc);
  R1 = MatX::Zero(nv, 3 * nv);
  R2 = C = Lam = MatX::Zero(nc, 3 * nv);
}

Mat6 se3RightJacobian(const Vec6& e) {
  Mat6 ad = Mat6::Zero();  // ad_e m = e x m (crossMotion)
  ad.topLeftCorner<3, 3>() = ad.bottomRightCorner<3, 3>() = skew(e.tail<3>());
  ad.topRightCorner<3, 3>() = skew(e.head<3>());
  Mat6 term = Mat6::Identity(), sum = Mat6::Identity();
  // Terms shrink like |ad|^k / (k + 1)!: at |ad| <= 10 (errors of metres and
  // a half turn) they are below 1e-17 of the sum by k = 60.
  for (int k = 1; k <= 80; ++k) {
    term = (-ad * term) / double(k + 1);
    sum += term;
    if (term.cwiseAbs().maxCoeff() <= 1e-18 * sum.cwiseAbs().maxCoeff()) break;
  }
  return sum;
}

namespace {

// Column c of a 6 x nv tangent as a fixed-size vector.
Vec6 col6(const MatX& T, int c) { return T.col(c); }

// The primal RNEA values and the tangents of v_i, a_i (fixed qdd) and the
// accumulated f_i (fixed qdd, lambda) along every q and v direction. Perturbing
// joint i by dq_i moves its placement to liMi Exp(xi), xi = S_i dq_i, so a
// motion carried from the parent, X^-1 m, moves by -xi x X^-1 m, and a force
// carried to the parent, X f, by X (xi x* f).
void tangentSweep(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v, const VecX& qdd,
                  const VecX* lambda) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  forwardKinematics(sys, d, q, v);  // liMi, oMi, v_i, c_i
  dd.a[0] = stack(-m.gravity, Vec3::Zero());
  dd.g[0] = dd.a[0];
  for (int i = 1; i < N; ++i) {
    const Joint& j = m.bodies[i].joint;
    const int p = m.bodies[i].parent, o = j.idx_v, n = j.nv, end = o + n;  // ancestors' columns are < end
    const SE3& X = d.liMi[i];
    const Vec6 vJ = d.S[i] * v.segment(o, n);
    const Vec6 vp = X.actInvMotion(d.v[p]), ap = X.actInvMotion(dd.a[p]), gp = X.actInvMotion(dd.g[p]);
    dd.a[i] = ap + d.S[i] * qdd.segment(o, n) + d.c[i];
    dd.g[i] = gp;
    for (MatX* t : {&dd.dv_dq[i], &dd.dv_dv[i], &dd.da_dq[i], &dd.da_dv[i], &dd.dg_dq[i]}) t->setZero();
    for (int c = 0; c < o; ++c) {  // carried from the parent
      dd.dv_dq[i].col(c) = X.actInvMotion(col6(dd.dv_dq[p], c));
      dd.dv_dv[i].col(c) = X.actInvMotion(col6(dd.dv_dv[p], c));
      dd.da_dq[i].col(c) = X.actInvMotion(col6(dd.da_dq[p], c));
      dd.da_dv[i].col(c) = X.actInvMotion(col6(dd.da_dv[p], c));
      dd.dg_dq[i].col(c) = X.actInvMotion(col6(dd.dg_dq[p], c));
    }
    for (int k = 0; k < n; ++k) {  // the joint's own directions
      const Vec6 Sk = d.S[i].col(k);
      dd.dv_dq[i].col(o + k) = crossMotion(vp, Sk);  // -xi x (X^-1 v_p)
      dd.dv_dv[i].col(o + k) = Sk;
      dd.da_dq[i].col(o + k) = crossMotion(ap, Sk);
      dd.dg_dq[i].col(o + k) = crossMotion(gp, Sk);
    }
    // c_i = v_i x vJ: d c = dv_i x vJ + v_i x d vJ (vJ = S v_j moves with v only).
    for (int c = 0; c < end; ++c) {
      dd.da_dq[i].col(c) += crossMotion(col6(dd.dv_dq[i], c), vJ);
      dd.da_dv[i].col(c) += crossMotion(col6(dd.dv_dv[i], c), vJ);
    }
    for (int k = 0; k < n; ++k) dd.da_dv[i].col(o + k) += crossMotion(d.v[i], d.S[i].col(k));
    // f_i = I a_i + v_i x* I v_i: d f = I da + dv x* I v + v x* I dv.
    const Vec6 Iv = d.I[i] * d.v[i];
    dd.f[i] = d.I[i] * dd.a[i] + crossForce(d.v[i], Iv);
    dd.df_dq[i].setZero();
    dd.df_dv[i].setZero();
    for (int c = 0; c < end; ++c) {
      const Vec6 dvq = dd.dv_dq[i].col(c), dvv = dd.dv_dv[i].col(c);
      dd.df_dq[i].col(c) = d.I[i] * col6(dd.da_dq[i], c) + crossForce(dvq, Iv) + crossForce(d.v[i], d.I[i] * dvq);
      dd.df_dv[i].col(c) = d.I[i] * col6(dd.da_dv[i], c) + crossForce(dvv, Iv) + crossForce(d.v[i], d.I[i] * dvv);
    }
  }
  // The constraint forces K_c^T lambda_c are constant in body coordinates.
  if (lambda != nullptr)
    for (const Constraint& c : sys.constraints)
      if (c.body > 0)
        dd.f[c.body] += c.placement.motionMatrixInv().topRows(c.rows()).transpose() * lambda->segment(c.row, c.rows());
  // Backward: tau_i = S_i^T f_i; f_p += X f_i.
  for (int i = N - 1; i >= 1; --i) {
    const Joint& j = m.bodies[i].joint;
    const int p = m.bodies[i].parent, o = j.idx_v, n = j.nv, end = d.subtreeDofEnd[i];
    const SE3& X = d.liMi[i];
    dd.dtau_dq.middleRows(o, n).noalias() = d.S[i].transpose() * dd.df_dq[i];
    dd.dtau_dv.middleRows(o, n).noalias() = d.S[i].transpose() * dd.df_dv[i];
    if (p == 0) continue;
    for (int c = 0; c < end; ++c) {  // ancestors', own and descendants' columns
      dd.df_dq[p].col(c) += X.actForce(col6(dd.df_dq[i], c));
      dd.df_dv[p].col(c) += X.actForce(col6(dd.df_dv[i], c));
    }
    for (int k = 0; k < n; ++k) dd.df_dq[p].col(o + k) += X.actForce(crossForce(d.S[i].col(k), dd.f[i]));
    dd.f[p] += X.actForce(dd.f[i]);
  }
}

}  // namespace

// J, the derivatives of alpha = J qdd + gamma (6d: the frame's spatial
// acceleration in C; 3d: the classical acceleration of its origin in C, a_lin +
// w x v_lin) and of the Baumgarte target a* = -kd v_C - kp e (docs/derivatives.md §2).
void constraintRowTangents(const System& sys, Data& d, DerivativeData& dd) {
  const int nv = sys.model.nv;
  for (const Constraint& c : sys.constraints) {
    const int r = c.rows(), b = c.body, row = c.row;
    auto J = dd.J.middleRows(row, r);
    auto dAq = dd.dalpha_dq.middleRows(row, r), dAv = dd.dalpha_dv.middleRows(row, r);
    auto dSq = dd.dastar_dq.middleRows(row, r), dSv = dd.dastar_dv.middleRows(row, r);
    if (b == 0) {  // a frame on the world: rows of zeros, which nothing moves
      J.setZero();
      dAq.setZero();
      dAv.setZero();
      dSq.setZero();
      dSv.setZero();
      continue;
    }
    const Mat6 cXi = c.placement.motionMatrixInv();
    const Vec6 vC = cXi * d.v[b];
    for (int k = 0; k < nv; ++k) {
      const Vec6 J6 = cXi * col6(dd.dv_dv[b], k);         // frame Jacobian column (C coordinates)
      const Vec6 dvq = cXi * col6(dd.dv_dq[b], k);        // d v_C / dq_k
      const Vec6 daq = cXi * (col6(dd.da_dq[b], k) - col6(dd.dg_dq[b], k));  // true acceleration
      const Vec6 dav = cXi * col6(dd.da_dv[b], k);
      J.col(k) = J6.head(r);
      if (c.type == ConstraintType::Weld6D) {
        dAq.col(k) = daq;
        dAv.col(k) = dav;
      } else {  // d(w x v) = dw x v + w x dv
        dAq.col(k) = daq.head<3>() + dvq.tail<3>().cross(vC.head<3>()) + vC.tail<3>().cross(dvq.head<3>());
        dAv.col(k) = dav.head<3>() + J6.tail<3>().cross(vC.head<3>()) + vC.tail<3>().cross(J6.head<3>());
      }
      dSq.col(k) = -c.kd * dvq.head(r);
      dSv.col(k) = -c.kd * J6.head(r);
    }
    if (c.kp == 0) continue;
    // The placement error moves with the frame: oMc(q (+) dq) = oMc Exp(J6 dq).
    const SE3 oMc = d.oMi[b] * c.placement;
    if (c.type == ConstraintType::Weld6D) {  // e = log(T^-1 oMc): de = Jr(e)^-1 J6 dq
      const Mat6 JrInv = se3RightJacobian(log6(c.target.inverse() * oMc)).inverse();
      for (int k = 0; k < nv; ++k) dSq.col(k) -= c.kp * (JrInv * (cXi * col6(dd.dv_dv[b], k)));
    } else {  // e = R^T (p - p_t): de = v dq + e x w dq
      const Vec3 e = oMc.R.transpose() * (oMc.p - c.target.p);
      for (int k = 0; k < nv; ++k) {
        const Vec6 J6 = cXi * col6(dd.dv_dv[b], k);
        dSq.col(k) -= c.kp * (J6.head<3>() + e.cross(J6.tail<3>()));
      }
    }
  }
}

void inverseDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                const VecX& qdd, const VecX* lambda) {
  tangentSweep(sys, d, dd, q, v, qdd, lambda);
  constraintRowTangents(sys, d, dd);
}

void forwardDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                const VecX& tau) {
  dd.qdd = aba(sys, d, q, v, tau);
  dd.lltM.compute(crba(sys, d, q));
  tangentSweep(sys, d, dd, q, v, dd.qdd, nullptr);
  // M dqdd + dtau/dx = dtau_in/dx at the solution.
  dd.dqdd_dq = -dd.dtau_dq;
  dd.lltM.solveInPlace(dd.dqdd_dq);
  dd.dqdd_dv = -dd.dtau_dv;
  dd.lltM.solveInPlace(dd.dqdd_dv);
  dd.dqdd_dtau.setIdentity();
  dd.lltM.solveInPlace(dd.dqdd_dtau);
}

void constrainedDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                    const VecX& tau, double mu, int iterations) {
  const int nv = sys.model.nv, nc = sys.nc;
  proxPv(sys, d, q, v, tau, mu, iterations);
  dd.qdd = d.qdd;
  dd.lambda = d.lambda;
  dd.lltM.compute(crba(sys, d, q));
  inverseDynamicsDerivatives(sys, d, dd, q, v, dd.qdd, &dd.lambda);

  // Right-hand sides for the inputs [q | v | tau].
  dd.R1.leftCols(nv) = -dd.dtau_dq;
  dd.R1.middleCols(nv, nv) = -dd.dtau_dv;
  dd.R1.rightCols(nv).setIdentity();
  dd.R2.leftCols(nv) = dd.dastar_dq - dd.dalpha_dq;
  dd.R2.middleCols(nv, nv) = dd.dastar_dv - dd.dalpha_dv;
  dd.R2.rightCols(nv).setZero();
  if (nc > 0) {
    dd.MinvJt = dd.J.transpose();
    dd.lltM.solveInPlace(dd.MinvJt);
    dd.G.noalias() = dd.J * dd.MinvJt;
    dd.G.diagonal().array() += 1.0 / mu;
    dd.lltG.compute(dd.G);
  }
  // One input at a time (nv columns): the products' blocking buffers then fit
  // Eigen's stack allocation on the largest robots (no heap in a call).
  for (int b = 0; b < 3; ++b) {
    auto X = dd.R1.middleCols(b * nv, nv);
    dd.lltM.solveInPlace(X);  // now M^-1 R1
    if (nc == 0) continue;
    auto C = dd.C.middleCols(b * nv, nv), L = dd.Lam.middleCols(b * nv, nv);
    C.noalias() = dd.J * X;
    C -= dd.R2.middleCols(b * nv, nv);
    // The proximal steps of the forward solve, on the tangents.
    L.setZero();
    for (int k = 0; k < iterations; ++k) {
      L = C + L / mu;
      dd.lltG.solveInPlace(L);
    }
    X.noalias() -= dd.MinvJt * L;  // X = M^-1 (R1 - J^T L)
  }
  if (nc > 0) {
    dd.dlambda_dq = dd.Lam.leftCols(nv);
    dd.dlambda_dv = dd.Lam.middleCols(nv, nv);
    dd.dlambda_dtau = dd.Lam.rightCols(nv);
  }
  dd.dqdd_dq = dd.R1.leftCols(nv);
  dd.dqdd_dv = dd.R1.middleCols(nv, nv);
  dd.dqdd_dtau = dd.R1.rightCols(nv);
}

}  // namespace proxgen

#include "algorithms/aba.hpp"

#include "algorithms/kinematics.hpp"

namespace proxgen {
namespace aba_steps {

void initialise(const System& sys, Data& d, const VecX& q, const VecX& v) {
  forwardKinematics(sys, d, q, v);
  for (int i = 1; i < sys.model.numBodies(); ++i) {
    d.IA[i] = d.I[i];
    d.pA[i] = crossForce(d.v[i], d.I[i] * d.v[i]);
  }
}

void eliminate(const System& sys, Data& d, int i, const VecX& tau) {
  const Joint& j = sys.model.bodies[i].joint;
  const int p = sys.model.bodies[i].parent;
  if (j.nv == 1) {  // almost every joint: D is a scalar
    const Vec6 S = d.S[i].col(0);
    const Vec6 U = d.IA[i] * S;
    const double Dinv = 1.0 / S.dot(U);
    d.U[i] = U;
    d.Dinv[i](0, 0) = Dinv;
    d.u[i](0) = tau[j.idx_v] - S.dot(d.pA[i]);
    if (p == 0) return;
    const Mat6 Ia = d.IA[i] - (Dinv * U) * U.transpose();
    const Vec6 pa = d.pA[i] + Ia * d.c[i] + (Dinv * d.u[i](0)) * U;
    d.IA[p] += d.liMi[i].actInertia(Ia);
    d.pA[p] += d.liMi[i].actForce(pa);
    return;
  }
  if (j.type == JointType::Planar) {  // S = three columns of the identity (x, y, yaw), constant
    using Mat63 = Eigen::Matrix<double, 6, 3>;
    const Mat63 S = d.S[i];
    const Mat63 U = d.IA[i] * S;
    const Mat3 Dinv = Mat3(S.transpose() * U).inverse();
    d.U[i] = U;
    d.Dinv[i] = Dinv;
    d.u[i] = tau.segment<3>(j.idx_v) - S.transpose() * d.pA[i];
    if (p == 0) return;
    const Mat63 UDinv = U * Dinv;
    const Mat6 Ia = d.IA[i] - UDinv * U.transpose();
    const Vec6 pa = d.pA[i] + Ia * d.c[i] + UDinv * Vec3(d.u[i]);
    d.IA[p] += d.liMi[i].actInertia(Ia);
    d.pA[p] += d.liMi[i].actForce(pa);
    return;
  }
  // The free flyer (S = identity): U = IA, D = IA.
  d.U[i] = d.IA[i];
  d.Dinv[i] = Mat6(d.IA[i]).inverse();
  d.u[i] = tau.segment<6>(j.idx_v) - d.pA[i];
  if (p == 0) return;
  const Mat6 UDinv = d.U[i] * d.Dinv[i];
  const Mat6 Ia = d.IA[i] - UDinv * d.U[i].transpose();
  const Vec6 pa = d.pA[i] + Ia * d.c[i] + UDinv * d.u[i];
  d.IA[p] += d.liMi[i].actInertia(Ia);
  d.pA[p] += d.liMi[i].actForce(pa);
}

void accelerate(const System& sys, Data& d, int i) {
  const Joint& j = sys.model.bodies[i].joint;
  const Vec6 a = d.liMi[i].actInvMotion(d.a[sys.model.bodies[i].parent]) + d.c[i];
  if (j.nv == 1) {
    const double qdd = d.Dinv[i](0, 0) * (d.u[i](0) - d.U[i].col(0).dot(a));
    d.qdd[j.idx_v] = qdd;
    d.a[i] = a + qdd * d.S[i].col(0);
    return;
  }
  if (j.type == JointType::Planar) {
    const Eigen::Matrix<double, 6, 3> S = d.S[i], U = d.U[i];
    const Vec3 qdd = Mat3(d.Dinv[i]) * (Vec3(d.u[i]) - U.transpose() * a);
    d.qdd.segment<3>(j.idx_v) = qdd;
    d.a[i] = a + S * qdd;
    return;
  }
  const Vec6 qdd = Mat6(d.Dinv[i]) * (Vec6(d.u[i]) - Mat6(d.U[i]).transpose() * a);  // free flyer
  d.qdd.segment<6>(j.idx_v) = qdd;
  d.a[i] = a + qdd;
}

void setRootAcceleration(const System& sys, Data& d) { d.a[0] = stack(-sys.model.gravity, Vec3::Zero()); }

}  // namespace aba_steps

const VecX& aba(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau) {
  const int N = sys.model.numBodies();
  aba_steps::initialise(sys, d, q, v);
  for (int i = N - 1; i >= 1; --i) aba_steps::eliminate(sys, d, i, tau);
  aba_steps::setRootAcceleration(sys, d);
  for (int i = 1; i < N; ++i) aba_steps::accelerate(sys, d, i);
  return d.qdd;
}

}  // namespace proxgen

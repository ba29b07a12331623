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
  d.U[i].noalias() = d.IA[i] * d.S[i];
  d.Dinv[i] = (d.S[i].transpose() * d.U[i]).inverse();
  d.u[i] = tau.segment(j.idx_v, j.nv) - d.S[i].transpose() * d.pA[i];
  const int p = sys.model.bodies[i].parent;
  if (p == 0) return;
  const Mat6N UDinv = d.U[i] * d.Dinv[i];
  const Mat6 Ia = d.IA[i] - UDinv * d.U[i].transpose();
  const Vec6 pa = d.pA[i] + Ia * d.c[i] + UDinv * d.u[i];
  const Mat6 X = d.liMi[i].motionMatrixInv();
  d.IA[p].noalias() += X.transpose() * Ia * X;
  d.pA[p] += d.liMi[i].actForce(pa);
}

void accelerate(const System& sys, Data& d, int i) {
  const Joint& j = sys.model.bodies[i].joint;
  const Vec6 a = d.liMi[i].actInvMotion(d.a[sys.model.bodies[i].parent]) + d.c[i];
  d.qdd.segment(j.idx_v, j.nv) = d.Dinv[i] * (d.u[i] - d.U[i].transpose() * a);
  d.a[i] = a + d.S[i] * d.qdd.segment(j.idx_v, j.nv);
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

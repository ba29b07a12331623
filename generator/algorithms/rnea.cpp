#include "algorithms/rnea.hpp"

#include "algorithms/kinematics.hpp"

namespace proxgen {

const VecX& rnea(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd) {
  const Model& m = sys.model;
  forwardKinematics(sys, d, q, v);
  d.a[0] = stack(-m.gravity, Vec3::Zero());  // gravity as a base acceleration
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    d.a[i] = d.liMi[i].actInvMotion(d.a[m.bodies[i].parent]) + d.S[i] * qdd.segment(j.idx_v, j.nv) + d.c[i];
    d.f[i] = d.I[i] * d.a[i] + crossForce(d.v[i], d.I[i] * d.v[i]);
  }
  for (int i = m.numBodies() - 1; i >= 1; --i) {
    const Joint& j = m.bodies[i].joint;
    d.tau.segment(j.idx_v, j.nv) = d.S[i].transpose() * d.f[i];
    const int p = m.bodies[i].parent;
    if (p > 0) d.f[p] += d.liMi[i].actForce(d.f[i]);
  }
  return d.tau;
}

const VecX& nonLinearEffects(const System& sys, Data& d, const VecX& q, const VecX& v) {
  d.h = rnea(sys, d, q, v, d.zeroV);  // no temporary: allocation-free (docs/dynamics.md)
  return d.h;
}

}  // namespace proxgen

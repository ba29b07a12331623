#include "algorithms/kinematics.hpp"

namespace proxgen {

void forwardKinematics(const System& sys, Data& d, const VecX& q) {
  const Model& m = sys.model;
  d.oMi[0] = SE3::Identity();
  for (int i = 1; i < m.numBodies(); ++i) {
    d.liMi[i] = m.jointPlacement(i, q);
    d.oMi[i] = d.oMi[m.bodies[i].parent] * d.liMi[i];
  }
}

void forwardKinematics(const System& sys, Data& d, const VecX& q, const VecX& v) {
  forwardKinematics(sys, d, q);
  const Model& m = sys.model;
  d.v[0].setZero();
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    const Vec6 vJ = d.S[i] * v.segment(j.idx_v, j.nv);
    d.v[i] = d.liMi[i].actInvMotion(d.v[m.bodies[i].parent]) + vJ;
    d.c[i] = crossMotion(d.v[i], vJ);
  }
}

void forwardKinematics(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd) {
  forwardKinematics(sys, d, q, v);
  const Model& m = sys.model;
  d.a[0].setZero();
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    d.a[i] = d.liMi[i].actInvMotion(d.a[m.bodies[i].parent]) + d.S[i] * qdd.segment(j.idx_v, j.nv) + d.c[i];
  }
}

SE3 framePlacement(const Data& d, int body, const SE3& inBody) { return d.oMi[body] * inBody; }

Vec6 frameVelocity(const Data& d, int body, const SE3& inBody) { return inBody.actInvMotion(d.v[body]); }

Vec6 frameAcceleration(const Data& d, int body, const SE3& inBody) { return inBody.actInvMotion(d.a[body]); }

Vec3 frameClassicalAcceleration(const Data& d, int body, const SE3& inBody) {
  const Vec6 vC = frameVelocity(d, body, inBody);
  const Vec6 aC = frameAcceleration(d, body, inBody);
  return aC.head<3>() + vC.tail<3>().cross(vC.head<3>());
}

Vec6 log6(const SE3& M) {
  const Eigen::AngleAxisd aa(M.R);
  const double t = aa.angle();
  const Vec3 w = t * aa.axis();
  // Inverse of the left Jacobian of SO(3): v = Jinv(w) p.
  Mat3 Jinv = Mat3::Identity() - 0.5 * skew(w);
  // coef = (1 - (t/2) cot(t/2)) / t^2 loses about 24 eps / t^4 relative to
  // cancellation; below t = 0.25 use its series (x cot x expanded), whose first
  // omitted term is < 1e-15 relative there.
  const double t2 = t * t;
  const double coef = t > 0.25 ? (1.0 - t * std::sin(t) / (2.0 * (1.0 - std::cos(t)))) / t2
                               : 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 / 47900160.0)));
  Jinv += coef * skew(w) * skew(w);
  return stack(Jinv * M.p, w);
}

}  // namespace proxgen

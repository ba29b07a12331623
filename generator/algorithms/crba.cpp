#include "algorithms/crba.hpp"

#include "algorithms/kinematics.hpp"

namespace proxgen {

const MatX& crba(const System& sys, Data& d, const VecX& q) {
  const Model& m = sys.model;
  forwardKinematics(sys, d, q);
  for (int i = 1; i < m.numBodies(); ++i) d.Ic[i] = d.I[i];
  d.M.setZero();
  for (int i = m.numBodies() - 1; i >= 1; --i) {
    const Joint& ji = m.bodies[i].joint;
    if (ji.nv == 1) {
      // Almost every joint: one column, F = Ic S carried down to the root as a
      // plain 6-vector, and each entry of M one dot product.
      Vec6 F = d.Ic[i] * d.S[i].col(0);
      d.M(ji.idx_v, ji.idx_v) = d.S[i].col(0).dot(F);
      for (int j = i; m.bodies[j].parent > 0; j = m.bodies[j].parent) {
        F = d.liMi[j].actForce(F);
        const int p = m.bodies[j].parent;
        const Joint& jp = m.bodies[p].joint;
        if (jp.nv == 1) {
          d.M(jp.idx_v, ji.idx_v) = d.S[p].col(0).dot(F);
          d.M(ji.idx_v, jp.idx_v) = d.M(jp.idx_v, ji.idx_v);
        } else {  // the free flyer above
          d.M.block(jp.idx_v, ji.idx_v, jp.nv, 1) = d.S[p].transpose() * F;
          d.M.block(ji.idx_v, jp.idx_v, 1, jp.nv) = d.M.block(jp.idx_v, ji.idx_v, jp.nv, 1).transpose();
        }
      }
    } else {
      Mat6N F = d.Ic[i] * d.S[i];  // composite force of unit joint accelerations
      d.M.block(ji.idx_v, ji.idx_v, ji.nv, ji.nv) = d.S[i].transpose() * F;
      for (int j = i; m.bodies[j].parent > 0; j = m.bodies[j].parent) {
        for (int col = 0; col < F.cols(); ++col) F.col(col) = d.liMi[j].actForce(F.col(col));
        const int p = m.bodies[j].parent;
        const Joint& jp = m.bodies[p].joint;
        d.M.block(jp.idx_v, ji.idx_v, jp.nv, ji.nv) = d.S[p].transpose() * F;
        d.M.block(ji.idx_v, jp.idx_v, ji.nv, jp.nv) = d.M.block(jp.idx_v, ji.idx_v, jp.nv, ji.nv).transpose();
      }
    }
    const int p = m.bodies[i].parent;
    if (p > 0) {
      d.Ic[p] += d.liMi[i].actInertia(d.Ic[i]);
    }
  }
  return d.M;
}

}  // namespace proxgen

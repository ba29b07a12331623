#include "algorithms/inverse_dynamics.hpp"

#include "algorithms/rnea.hpp"

namespace proxgen {

void addConstraintForces(const System& sys, Data& d, const VecX& lambda) {
  const Model& m = sys.model;
  for (int i = 1; i < m.numBodies(); ++i) d.f[i].setZero();
  // The rows of constraint c are K_c v_i (K_c: the body-to-C motion transform,
  // 3 linear rows for a point), so J_c^T lambda_c is the generalised force of
  // the body force K_c^T lambda_c on body i.
  for (const Constraint& c : sys.constraints) {
    if (c.body == 0) continue;  // rows on the world: zero rows of J
    const Mat6 cXi = c.placement.motionMatrixInv();
    d.f[c.body].noalias() += cXi.topRows(c.rows()).transpose() * lambda.segment(c.row, c.rows());
  }
  for (int i = m.numBodies() - 1; i >= 1; --i) {
    const Joint& j = m.bodies[i].joint;
    d.tau.segment(j.idx_v, j.nv).noalias() += d.S[i].transpose() * d.f[i];
    const int p = m.bodies[i].parent;
    if (p > 0) d.f[p] += d.liMi[i].actForce(d.f[i]);
  }
}

const VecX& inverseDynamics(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd,
                            const VecX* lambda) {
  rnea(sys, d, q, v, qdd);
  if (lambda != nullptr && sys.nc > 0) addConstraintForces(sys, d, *lambda);
  return d.tau;
}

}  // namespace proxgen

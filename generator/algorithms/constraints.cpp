#include "algorithms/constraints.hpp"

#include <stdexcept>

#include "algorithms/kinematics.hpp"

namespace proxgen {

VecN baumgarteTarget(const Constraint& c, const SE3& oMc, const Vec6& vC) {
  const int r = c.rows();
  VecN aStar = VecN::Zero(r);
  if (c.kd != 0) aStar -= c.kd * vC.head(r);
  if (c.kp != 0) {
    if (c.type == ConstraintType::Weld6D) aStar -= c.kp * log6(c.target.inverse() * oMc);
    else aStar -= c.kp * (oMc.R.transpose() * (oMc.p - c.target.p));
  }
  return aStar;
}

System activeSubsystem(const System& sys, const std::vector<bool>& active) {
  if (active.size() != sys.constraints.size()) throw std::invalid_argument("activeSubsystem: one flag per constraint");
  System sub = sys;
  sub.constraints.clear();
  int row = 0;
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    if (!active[k]) continue;
    Constraint c = sys.constraints[k];
    c.row = row;
    row += c.rows();
    sub.constraints.push_back(c);
  }
  sub.nc = row;
  return sub;
}

std::vector<int> activeRows(const System& sys, const std::vector<bool>& active) {
  std::vector<int> rows;
  for (std::size_t k = 0; k < sys.constraints.size(); ++k)
    if (active.at(k))
      for (int j = 0; j < sys.constraints[k].rows(); ++j) rows.push_back(sys.constraints[k].row + j);
  return rows;
}

void computeConstraintTerms(const System& sys, Data& d) {
  const Vec6 ag = stack(sys.model.gravity, Vec3::Zero());
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    ConstraintTerm& t = d.terms[k];
    const int r = c.rows();
    const Mat6 cXi = c.placement.motionMatrixInv();  // body -> constraint frame
    t.K = cXi.topRows(r);
    const Vec6 vC = cXi * d.v[c.body];
    t.k = baumgarteTarget(c, d.oMi[c.body] * c.placement, vC);
    if (c.type == ConstraintType::Point3D) t.k -= vC.tail<3>().cross(vC.head<3>());  // drift w_C x v_C
    t.k -= t.K * d.oMi[c.body].actInvMotion(ag);  // gravity shift of a_i
  }
}

double constraintResidual(const System& sys, const Data& d) {
  double sq = 0;
  for (std::size_t k = 0; k < sys.constraints.size(); ++k)
    sq += (d.terms[k].K * d.a[sys.constraints[k].body] - d.terms[k].k).squaredNorm();
  return std::sqrt(sq);
}

}  // namespace proxgen

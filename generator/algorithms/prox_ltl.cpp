#include "algorithms/prox_ltl.hpp"

#include "algorithms/joint_space.hpp"

namespace proxgen {
namespace {

using joint_space::lastDof;

// Y = J L^-1 (kept in d.JMinv), row by row: L^T y = j, scattered along the
// ancestor chain of the constraint's body, the only place row j is non-zero.
void rowsTimesLinv(const System& sys, Data& d) {
  const std::vector<int>& parent = d.dofParent;
  d.JMinv = d.J;
  for (const Constraint& c : sys.constraints)
    for (int r = c.row; r < c.row + c.rows(); ++r)
      for (int i = lastDof(sys.model, c.body); i >= 0; i = parent[i])
        for (int j = parent[i]; j >= 0; j = parent[j]) d.JMinv(r, j) -= d.LD(i, j) * d.JMinv(r, i);
}

// G = J M^-1 J^T = Y D^-1 Y^T. Rows of two constraints meet only on their
// common ancestors: the walk starts at the deepest dof both chains share
// (dofs are numbered parents first, so the larger index steps up).
void delassus(const System& sys, Data& d) {
  const std::vector<int>& parent = d.dofParent;
  const MatX& Y = d.JMinv;
  d.work.head(sys.model.nv) = d.LD.diagonal().cwiseInverse();  // D^-1
  for (std::size_t a = 0; a < sys.constraints.size(); ++a) {
    const Constraint& ca = sys.constraints[a];
    for (std::size_t b = a; b < sys.constraints.size(); ++b) {
      const Constraint& cb = sys.constraints[b];
      int common = lastDof(sys.model, ca.body);
      for (int other = lastDof(sys.model, cb.body); common != other;) {
        if (common > other) common = parent[common];
        else other = parent[other];
      }
      for (int ra = ca.row; ra < ca.row + ca.rows(); ++ra)
        for (int rb = cb.row; rb < cb.row + cb.rows(); ++rb) {
          double g = 0;
          for (int k = common; k >= 0; k = parent[k]) g += Y(ra, k) * d.work[k] * Y(rb, k);
          d.G(ra, rb) = g;
          d.G(rb, ra) = g;
        }
    }
  }
}

}  // namespace

void proxLtl(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations) {
  const std::vector<int>& parent = d.dofParent;
  const int nv = sys.model.nv;
  joint_space::assemble(sys, d, q, v);
  d.LD = d.M;
  joint_space::factorLtdl(parent, d.LD);

  // z = L^-T (tau - h): qdd_free = L^-1 D^-1 z, J qdd_free = Y D^-1 z.
  d.jsB = tau - d.h;
  joint_space::solveLt(parent, d.LD, d.jsB);
  rowsTimesLinv(sys, d);
  d.lambda.setZero();
  if (sys.nc > 0 && iterations > 0) {
    delassus(sys, d);
    d.work.head(nv) = d.jsB.cwiseQuotient(d.LD.diagonal());
    d.yfree.noalias() = d.JMinv * d.work.head(nv);
    d.yfree += d.gamma - d.aStar;
    // (G + I/mu) lambda+ = y_free + lambda / mu (docs/algorithms.md §3 and §4.2).
    d.G.diagonal().array() += 1.0 / mu;
    d.llt.compute(d.G);
    for (int k = 0; k < iterations; ++k) {
      d.rhs = d.yfree + d.lambda / mu;
      d.lambda = d.llt.solve(d.rhs);
    }
  }
  // qdd = M^-1 (tau - h - J^T lambda) = L^-1 D^-1 (z - Y^T lambda): one half solve.
  d.jsB.noalias() -= d.JMinv.transpose() * d.lambda;
  d.jsB.array() /= d.LD.diagonal().array();
  joint_space::solveL(parent, d.LD, d.jsB);
  d.qdd = d.jsB;
  d.iterationsDone = iterations;
  d.residual = joint_space::rowResidual(d);
}

}  // namespace proxgen

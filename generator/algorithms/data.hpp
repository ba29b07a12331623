// Preallocated work space of the generic solvers. Everything is sized once from
// the System; no algorithm allocates while it solves (per-body matrices have a
// fixed maximum size of 6 and live inside the vectors' elements).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "model/model.hpp"

namespace proxgen {

/// Up to 6 columns/rows, stored inline (no heap).
using Mat6N = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
using MatNN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using MatN6 = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6>;

/// Per-constraint quantities K (rows x 6) and k (rows) of docs/algorithms.md §2:
/// the constraint reads K a_i = k on its body's (gravity-shifted) acceleration.
struct ConstraintTerm {
  MatN6 K;
  VecN k;
};

struct Data {
  explicit Data(const System& sys);

  // Constant per body (cached from the model).
  std::vector<Mat6> I;    // spatial inertia about the body origin
  std::vector<Mat6N> S;   // motion subspace

  // Kinematics.
  std::vector<SE3> liMi;  // body i in its parent, at q
  std::vector<SE3> oMi;   // body i in the world
  std::vector<Vec6> v;    // body twist, body coordinates
  std::vector<Vec6> a;    // body spatial acceleration (gravity-shifted inside ABA-type sweeps)
  std::vector<Vec6> c;    // velocity-product acceleration v_i x (S_i qd_i)

  // Articulated-body quantities.
  std::vector<Mat6> IA;
  std::vector<Vec6> pA;
  std::vector<Mat6N> U;    // IA S
  std::vector<MatNN> Dinv; // (S^T U)^-1
  std::vector<VecN> u;     // tau - S^T pA (accumulates multiplier terms in constrainedABA)
  std::vector<Vec6> dp;    // reduced-sweep force increments (constrainedABA)

  // Constraints.
  std::vector<ConstraintTerm> terms;  // one per constraint, layout order
  std::vector<int> support;           // bodies on the constraint support, ascending
  std::vector<char> onSupport;        // per body
  VecX lambda, dlambda;               // multipliers (stacked rows, layout order)

  // proxPV: rows of each body's subtree, in tree order.
  // Subtree i's rows are the contiguous block [subtreeStart[i], + m_(i)) of the
  // root's order, so lA_i and LA_i are blocks of yfree and G, summed in place.
  std::vector<std::vector<int>> subtreeRows;  // row indices (layout numbering) per body
  std::vector<int> subtreeStart;              // first tree-order row of each subtree
  std::vector<MatX> KA;   // 6 x m_(i)
  std::vector<MatX> KS;   // n_i x m_(i)
  std::vector<MatX> DinvKS;  // D_i^-1 KS_i
  MatX G;                 // Delassus (tree order; proxPV fills only its lower triangle)
  VecX yfree, lambdaTree, rhs;
  Eigen::LLT<MatX> llt;

  // Joint space.
  VecX qdd, tau, h;
  MatX M;           // joint-space inertia (CRBA)
  MatX J;           // stacked constraint Jacobian (nc x nv)
  VecX gamma;       // J qdd + gamma = constraint acceleration
  VecX aStar;       // constraint target acceleration
  std::vector<Mat6> Ic;  // composite inertias (CRBA)
  std::vector<Vec6> f;   // body forces (RNEA)
  std::vector<int> lastChild;  // for the LTL factorisation: parent of each dof
  std::vector<int> dofParent;  // lambda(i): parent dof of dof i (-1 at the root)
  MatX Mmu;          // M + mu J^T J (proxLTLs)
  MatX JMinv;        // workspace for proxLTL
  VecX work;

  // Joint-space algorithms (proxLTL, proxLTLs), appended.
  MatX LD;          // sparse L^T D L factor in place: D on the diagonal, L strictly below
  VecX jsB;         // right-hand side / intermediate of the sparse solves (nv)
  VecX rowRes;      // J qdd + gamma - aStar (nc, layout order)

  // Dynamics library (docs/dynamics.md), appended.
  VecX zeroV;                   // nv zeros: qdd = 0, v = 0 without a temporary
  VecX placements;              // 12 per constraint: world rotation (row-major), position
  VecX wrenches;                // 6 per constraint: force, torque on the robot in world axes
  MatX Minv;                    // M^-1 (mass_matrix_inverse), full
  std::vector<MatX> FA;         // per body 6 x nv: unit-torque forces, then accelerations (Minv)
  std::vector<int> subtreeDofEnd;  // one past the last dof of each body's subtree
  std::vector<Mat6> Phi;        // apparent inverse inertia of each support body (Delassus)
  std::vector<Mat6> Tkey;       // force map from the nearest key body below into body coordinates
  std::vector<int> keyBelow;    // that key body (-1 off the support)
  MatX delassusG;               // J M^-1 J^T (or with M + mu J^T J), layout order
  MatX delassusInv;             // (G + I/mu)^-1, layout order
  MatX JMinvLib;                // J M^-1 (nc x nv)

  int iterationsDone = 0;
  double residual = 0;  // ||J qdd + gamma - aStar|| of the last solve (when computed)
};

}  // namespace proxgen

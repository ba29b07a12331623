// Derivatives of the dynamics (docs/derivatives.md): of inverse dynamics, of
// the unconstrained forward dynamics (ABA) and of the constrained solution the
// proximal solvers converge to, with respect to the configuration, the
// velocity and the torque.
//
// Tangent convention (every "d/dq" here): a column k of d/dq is the
// derivative along q (+) t e_k, t -> 0, where q (+) dq is
//  - q + dq for revolute, continuous and prismatic joints;
//  - for the free flyer, the placement M(q) Exp(dq), dq = [linear; angular]
//    in the base frame (the right perturbation of Pinocchio's integrate);
//  - for a planar joint, likewise M(q) Exp([dx dy 0 0 0 dyaw]) in the joint's frame.
// In every case the perturbed joint placement is X_J(q) Exp(S dq_i), so the
// tangent space is the velocity space (nv columns) and S is constant.
//
// Signs are the solvers' (docs/algorithms.md §2): the constraint force on
// the robot is -J^T lambda, so M qdd + h + J^T lambda = tau.
#pragma once

#include <vector>

#include "algorithms/data.hpp"

namespace proxgen {

/// The buffers of the derivative sweeps, sized once from the System (no
/// allocation in a call). Results are read from the named matrices; all are
/// dense, row = output component, column = input component (nv or nc rows,
/// nv columns, layout order for constraint rows).
struct DerivativeData {
  explicit DerivativeData(const System& sys);

  // Primal values of the tangent sweep (body coordinates).
  std::vector<Vec6> a;   // gravity-shifted acceleration (RNEA's, a_0 = -a_g)
  std::vector<Vec6> g;   // the base's -a_g carried into body i (true acceleration = a - g)
  std::vector<Vec6> f;   // body force, accumulated over the subtree, constraint forces included
  // Tangents, 6 x nv per body: column k = derivative along input k.
  std::vector<MatX> dv_dq, dv_dv;  // body twist (dv_dv is the body Jacobian)
  std::vector<MatX> da_dq, da_dv;  // gravity-shifted acceleration at fixed qdd
  std::vector<MatX> dg_dq;         // the carried gravity term
  std::vector<MatX> df_dq, df_dv;  // accumulated body force at fixed qdd, lambda

  // Inverse dynamics derivatives (nv x nv).
  MatX dtau_dq, dtau_dv;
  // Constraint rows at fixed qdd (nc x nv): the acceleration J qdd + gamma and the target a*.
  MatX dalpha_dq, dalpha_dv, dastar_dq, dastar_dv;
  MatX J;  // nc x nv, the constraint rows (frame C), from the body Jacobians

  // Forward dynamics results.
  VecX qdd, lambda;
  MatX dqdd_dq, dqdd_dv, dqdd_dtau;           // nv x nv
  MatX dlambda_dq, dlambda_dv, dlambda_dtau;  // nc x nv

  // Solve workspace: the KKT right-hand sides for the 3 nv inputs [q | v | tau].
  Eigen::LLT<MatX> lltM, lltG;
  MatX MinvJt;   // M^-1 J^T (nv x nc)
  MatX G;        // J M^-1 J^T + I/mu (nc x nc)
  MatX R1, R2;   // nv x 3nv and nc x 3nv
  MatX C, Lam;   // nc x 3nv: J M^-1 R1 - R2, and the multiplier tangents
};

/// Derivatives of tau = RNEA(q, v, qdd) + J(q)^T lambda at fixed qdd and
/// lambda (lambda nullptr: no constraint forces): dd.dtau_dq, dd.dtau_dv.
/// One forward-mode tangent sweep through RNEA for all 2 nv directions at
/// once, O(N nv) (the zero columns above each body are skipped), exact (no
/// differences). Also fills, at this qdd, the constraint rows' derivatives
/// dd.dalpha_* (of J qdd + gamma), dd.dastar_* (of the Baumgarte target,
/// position and velocity terms) and dd.J. Overwrites d's kinematics.
void inverseDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                const VecX& qdd, const VecX* lambda);

/// The constraint rows at fixed qdd from the body tangents at the constrained
/// bodies (dd.dv_dq, dd.dv_dv, dd.da_dq, dd.da_dv, dd.dg_dq of each constraint's
/// body, zero outside its path's columns) and d's kinematics: dd.J,
/// dd.dalpha_dq, dd.dalpha_dv, dd.dastar_dq, dd.dastar_dv. The last step of
/// inverseDynamicsDerivatives and of inverseDynamicsDerivativesWorld.
void constraintRowTangents(const System& sys, Data& d, DerivativeData& dd);

/// Derivatives of qdd = ABA(q, v, tau) (no constraints): dd.qdd, and
/// dqdd/dq = -M^-1 dtau/dq, dqdd/dv = -M^-1 dtau/dv (at the ABA solution),
/// dqdd/dtau = M^-1, with M from CRBA and its Cholesky factor.
void forwardDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                const VecX& tau);

/// Derivatives of the constrained solution (dd.qdd, dd.lambda: proxPV's,
/// `iterations` proximal steps with `mu` from lambda = 0) with respect to q,
/// v and tau, by the implicit function theorem on
///   M qdd + h + J^T lambda = tau,   J qdd + gamma = a*(q, v)
/// at that solution, in the proximal limit (docs/derivatives.md): the tangents
/// (X, L) of (qdd, lambda) for the inputs [q | v | tau] solve
///   M X + J^T L = R1 = [-dtau/dq, -dtau/dv, I],
///   J X = R2 = [da*/dq - dalpha/dq, da*/dv - dalpha/dv, 0],
/// with L by the same `iterations` proximal steps
///   (J M^-1 J^T + I/mu) L+ = J M^-1 R1 - R2 + L/mu from L = 0,
/// whose limit is the minimum-norm L, and X = M^-1 (R1 - J^T L).
void constrainedDynamicsDerivatives(const System& sys, Data& d, DerivativeData& dd, const VecX& q, const VecX& v,
                                    const VecX& tau, double mu, int iterations);

/// The right Jacobian of the SE(3) exponential at a twist e = [linear; angular]:
/// Exp(e + t) = Exp(e) Exp(Jr(e) t + O(t^2)), so log(Exp(e) Exp(x)) = e +
/// Jr(e)^-1 x + O(x^2). Summed as its series sum_k (-ad_e)^k / (k + 1)! to
/// round-off (the generated code will use the closed form).
Mat6 se3RightJacobian(const Vec6& e);

}  // namespace proxgen

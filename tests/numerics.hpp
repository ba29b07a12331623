// Numerics shared by the verification suites (analytic, identities,
// equivalence, singular): round-off bounds argued from condition numbers, and
// the configuration-space integration that finite differences need.
#pragma once

#include <Eigen/Eigenvalues>
#include <limits>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "model/model.hpp"

namespace proxgen::test {

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// The four generic algorithms, with the class that sets their round-off
/// (primal: solve with M + mu J^T J; dual: with M and G, see below).
using Solver = void (*)(const System&, Data&, const VecX&, const VecX&, const VecX&, double, int);
struct Algorithm {
  const char* name;
  bool primal;
  Solver run;
};
inline const Algorithm kAlgorithms[] = {
    {"cABA", true, constrainedAba}, {"proxPV", false, proxPv}, {"proxLTL", false, proxLtl}, {"proxLTLs", true, proxLtls}};

/// Eigenvalues of the Jacobi-scaled symmetric positive (semi)definite matrix
/// D^-1/2 A D^-1/2, D = diag(A), ascending. A zero diagonal entry of a
/// semidefinite matrix means a zero row and column (a constraint row no joint
/// can move, e.g. along a stretched arm): it is left unscaled and stays a zero eigenvalue.
inline VecX scaledEigenvalues(const MatX& A) {
  const VecX s = A.diagonal().unaryExpr([](double x) { return x > 0 ? 1 / std::sqrt(x) : 1.0; });
  const MatX B = s.asDiagonal() * A * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<MatX>(B, Eigen::EigenvaluesOnly).eigenvalues();
}

/// Condition number of the Jacobi-scaled matrix on its range: eigenvalues at
/// or below min(size) eps times the largest count as zero (the rank rule of
/// LAPACK/MATLAB and of Eigen's CompleteOrthogonalDecomposition, which
/// denseExact uses). For a positive definite matrix it is the plain condition.
inline double scaledCondition(const MatX& A) {
  if (A.rows() == 0) return 1.0;
  const VecX ev = scaledEigenvalues(A);
  const double top = ev.maxCoeff(), zero = double(A.rows()) * kEps * top;
  double low = top;
  for (double e : ev)
    if (e > zero) low = std::min(low, e);
  return top / low;
}

// Round-off bounds. Every solver here is a chain of a few backward-stable
// eliminations (Cholesky / L^T D L / ABA are all Gaussian elimination on a
// symmetric positive definite matrix), so each returns the exact answer of a
// problem perturbed by ~ n eps in relative terms, and the forward error is
// that times a condition number (Higham, Accuracy and Stability, ch. 10).
// Cholesky-type eliminations are invariant under diagonal scaling, so the
// condition that governs them is the one of the Jacobi-scaled matrix (van der
// Sluis: within a factor n of the best diagonal scaling); it removes the mix of
// units (kg vs kg m^2, N vs Nm) that puts the raw cond(M) of the atlas at 1e8
// although its factorisation loses nothing near that much.
//  - dual algorithms (proxPV, proxLTL, dense): a solve with M, then
//    G = J M^-1 J^T and a solve with G + I/mu: kappa = kappa_s(M) + kappa_s(G)
//    (G on its range when it is singular);
//  - primal algorithms (cABA, proxLTLs): a solve with M_mu = M + mu J^T J
//    (cABA's articulated inertias IA + mu K^T K are its Schur complements):
//    kappa = kappa_s(M_mu), which grows with mu (docs/algorithms.md §3: cABA's
//    round-off grows with mu, proxPV's does not).
// bound = c n eps kappa, c = 10: two implementations' errors add (2) and each
// chains about five stable steps (factor, two triangular solves, the Delassus
// or penalty products, the multiplier update). Used as a relative error
// (test::relErr: max |a - b| / max(1, max |b|)).
constexpr double kC = 10.0;

struct Bounds {
  double dual, primal;
};

inline Bounds roundoffBounds(const DenseProblem& p, double mu) {
  const double n = double(p.M.rows());
  const MatX G = p.J * p.M.llt().solve(p.J.transpose());
  const MatX Mmu = p.M + mu * p.J.transpose() * p.J;
  return {kC * n * kEps * (scaledCondition(p.M) + scaledCondition(G)), kC * n * kEps * scaledCondition(Mmu)};
}

/// Round-off of qdd = qdd_free - M^-1 J^T lambda that comes from the size of
/// the multipliers rather than from conditioning: a relative c n eps on that
/// product, c n eps max(|M^-1 J^T| |lambda|). Negligible for moderate lambda;
/// it dominates for inconsistent rows, where lambda grows like K mu |y|.
inline double multiplierRoundoff(const DenseProblem& p, const VecX& lambda) {
  if (lambda.size() == 0) return 0.0;
  const MatX MinvJt = p.M.llt().solve(p.J.transpose()).cwiseAbs();
  return kC * double(p.M.rows()) * kEps * (MinvJt * lambda.cwiseAbs()).maxCoeff();
}

/// The dense iteration has settled in qdd (never judged on lambda, which grows
/// without bound for inconsistent rows): doubles K until qdd^K and qdd^2K agree
/// to tol (relative, plus the multiplier round-off above) and returns 2K. The
/// iterates converge geometrically (rate 1/(1 + mu g) per eigenvalue g > 0 of
/// G), so qdd^2K is then far closer to the limit than tol. Returns -1 if that
/// never happens below 4096 iterations.
inline int convergedIterations(const DenseProblem& p, double mu, double tol) {
  VecX a, b, la, lb;
  for (int K = 8; K <= 4096; K *= 2) {
    denseProx(p, mu, K, a, la);
    denseProx(p, mu, 2 * K, b, lb);
    const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
    if ((a - b).cwiseAbs().maxCoeff() <= tol * scale + multiplierRoundoff(p, lb)) return 2 * K;
  }
  return -1;
}

/// SE(3) exponential of a twist [linear; angular] (closed form; Taylor series
/// below 1e-4 rad, whose first dropped term is ~ t^4 ~ 1e-16).
inline SE3 exp6(const Vec6& xi) {
  const Vec3 v = xi.head<3>(), w = xi.tail<3>();
  const double t = w.norm();
  const Mat3 W = skew(w);
  const bool small = t < 1e-4;
  const double s = small ? 1 - t * t / 6 : std::sin(t) / t;
  const double a = small ? 0.5 - t * t / 24 : (1 - std::cos(t)) / (t * t);
  const double b = small ? 1.0 / 6 - t * t / 120 : (t - std::sin(t)) / (t * t * t);
  return {Mat3::Identity() + s * W + a * W * W, (Mat3::Identity() + a * W + b * W * W) * v};
}

/// The constraint rows' acceleration J qdd + gamma by central differences of
/// the constraint velocities: d0 holds the kinematics at (q, v), dp and dm at
/// q "+-" h v, v +- h qdd. 6D: the body-fixed frame's velocity in its own
/// coordinates, whose derivative is its spatial acceleration. 3D: the WORLD
/// velocity of the point differenced and rotated into C (differencing the
/// C-frame velocity would lose w x v).
inline VecX constraintRowsByDifferences(const System& sys, const Data& d0, const Data& dp, const Data& dm, double h) {
  VecX fd(sys.nc);
  for (const Constraint& k : sys.constraints) {
    const Vec6 vp = frameVelocity(dp, k.body, k.placement), vm = frameVelocity(dm, k.body, k.placement);
    if (k.type == ConstraintType::Weld6D) {
      fd.segment<6>(k.row) = (vp - vm) / (2 * h);
    } else {
      const Mat3 R0 = framePlacement(d0, k.body, k.placement).R;
      const Vec3 wp = framePlacement(dp, k.body, k.placement).R * vp.head<3>();
      const Vec3 wm = framePlacement(dm, k.body, k.placement).R * vm.head<3>();
      fd.segment<3>(k.row) = R0.transpose() * (wp - wm) / (2 * h);
    }
  }
  return fd;
}

/// q "+" dv: joint coordinates add; the free flyer moves by its body twist,
/// M(q') = M(q) exp(dv) (v is the twist in the base's own frame), and a planar
/// joint likewise by the planar twist [vx vy 0 0 0 wz] (exp6 keeps it planar).
inline VecX integrate(const Model& m, const VecX& q, const VecX& dv) {
  VecX out = q;
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    if (j.type == JointType::Planar) {
      const double c = q[j.idx_q + 2], s = q[j.idx_q + 3];
      Mat3 R;
      R << c, -s, 0, s, c, 0, 0, 0, 1;
      const SE3 M{R, Vec3(q[j.idx_q], q[j.idx_q + 1], 0)};
      Vec6 xi = Vec6::Zero();
      xi << dv[j.idx_v], dv[j.idx_v + 1], 0, 0, 0, dv[j.idx_v + 2];
      const SE3 Mp = M * exp6(xi);
      out.segment<4>(j.idx_q) << Mp.p[0], Mp.p[1], Mp.R(0, 0), Mp.R(1, 0);
      continue;
    }
    if (j.type != JointType::FreeFlyer) {
      out[j.idx_q] += dv[j.idx_v];
      continue;
    }
    const Eigen::Quaterniond quat(q[j.idx_q + 6], q[j.idx_q + 3], q[j.idx_q + 4], q[j.idx_q + 5]);
    const SE3 M{quat.toRotationMatrix(), q.segment<3>(j.idx_q)};
    const SE3 Mp = M * exp6(dv.segment<6>(j.idx_v));
    out.segment<3>(j.idx_q) = Mp.p;
    out.segment<4>(j.idx_q + 3) = Eigen::Quaterniond(Mp.R).coeffs();  // [x y z w]
  }
  return out;
}

/// The axial vector of the skew-symmetric part of A (angular velocity from R^T dR).
inline Vec3 vee(const Mat3& A) { return 0.5 * Vec3(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1)); }

}  // namespace proxgen::test

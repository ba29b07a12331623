// The generic side of the generated-solver tests (harness_lib.cpp, compiled
// once): harness.cpp, built once per solver, describes its solver with a
// SolverUnderTest and calls these from its tests.
#pragma once

#include <functional>
#include <vector>

#include "model/model.hpp"

// The harness's robot, as the per-solver files pass it on (a shared case, or a
// URDF and a layout: the compile definitions of tests/generated/CMakeLists.txt).
// Expanded only in the per-solver files, which have those definitions.
#ifdef PROXGEN_SOLVER_CASE
#define PROXGEN_SOLVER_INPUTS PROXGEN_SOLVER_CASE, nullptr, nullptr
#else
#define PROXGEN_SOLVER_INPUTS nullptr, PROXGEN_SOLVER_URDF, PROXGEN_SOLVER_LAYOUT
#endif

namespace proxgen::test {

/// One generated solver, seen through double-precision vectors.
struct SolverUnderTest {
  enum Algorithm { kConstrainedAba, kProxPv };
  int nq = 0, nv = 0, nc = 0;
  bool isFloat = false;  // Scalar = float: inputs are rounded to float before both solvers see them
  /// Runs the generated algorithm on (q, v, tau), already representable in its
  /// Scalar, with this mu and K; writes qdd (nv) and lambda (nc).
  std::function<void(Algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu, int K, VecX& qdd,
                     VecX& lambda)>
      run;
  /// The same with a warm start (lambda0: nc values, layout order, or null for
  /// Settings::lambda0 = nullptr); returns residual(w) of that solve.
  std::function<double(Algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu, int K, const VecX* lambda0,
                       VecX& qdd, VecX& lambda)>
      runFrom;
  /// The same with Settings::active = *active (ncons flags; null: the default).
  std::function<double(Algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu, int K, const VecX* lambda0,
                       const std::vector<bool>* active, VecX& qdd, VecX& lambda)>
      runScheduled;
};

/// The schedules a test runs for ncons constraints: every subset when
/// ncons <= 4, else none, each one alone, each one left out, all, and four
/// random ones (fixed seed).
std::vector<std::vector<bool>> testSchedules(int ncons);

/// The System a solver was generated from: a case of the shared cases.yaml
/// (caseName), or a URDF and a layout.
System loadSolverSystem(const char* caseName, const char* urdf, const char* layout);

/// 100 random states, K = 0, 1, 2, 3, 100, mu = 100 and 1e4: the generated
/// constrainedABA against constrainedAba and proxPV against proxPv, within the
/// bounds argued in harness_lib.cpp.
void expectMatchesTheGenericSolvers(const SolverUnderTest& solver, const System& sys);

/// The joint-space functions of one generated solver (empty: not held), in double.
struct LibraryUnderTest {
  bool isFloat = false;
  std::function<void(const VecX& q, const VecX& v, const VecX& qdd, const VecX* lambda, VecX& tau)> inverseDynamics;
  std::function<void(const VecX& q, const VecX& v, VecX& h)> nonlinearEffects;
  std::function<void(const VecX& q, MatX& M)> massMatrix, massMatrixInverse;
};

/// Random states (and random qdd, lambda): each function `lib` holds against its
/// generic twin (verify/compare.cpp's bounds), and the identities M Minv = I,
/// nonlinear_effects = inverse_dynamics(qdd = 0, nullptr) and, with `solver`
/// holding prox_pv (null: skipped), inverse_dynamics(q, v, qdd, lambda) = tau
/// at its answer (q, v, tau) -> (qdd, lambda).
void expectLibraryMatchesTheGeneric(const LibraryUnderTest& lib, const SolverUnderTest* solver, const System& sys);

// ---- the controller API of issue 18 (items 1 and 3): argued in harness_lib.cpp.
/// A free-flyer quaternion scaled by 2, -1, 0.5 gives the unit one's answer bit
/// for bit, scaled by 1e-3 and 1e3 the generic answer within the bounds.
void expectQuaternionScaleIsIgnored(const SolverUnderTest& solver, const System& sys);
/// Warm starts against the generic solvers' warm starts, and K = 1 from the
/// K-th iterate against iterate K + 1 (a converged lambda0 is a fixed point).
void expectWarmStartMatchesTheGeneric(const SolverUnderTest& solver, const System& sys);
/// Settings::active (issue 18 item 2) for testSchedules(ncons): the inactive
/// rows' lambda exactly 0, qdd and the active rows' lambda against the generic
/// solvers on activeSubsystem (the bounds of expectMatchesTheGenericSolvers, at
/// the sub-layout's conditioning), warm starts whose inactive rows hold NaN
/// giving the bits of lambda0 = 0 there, and residual(w) over the active rows.
void expectScheduleIsTheSubLayout(const SolverUnderTest& solver, const System& sys);
/// residual(w) against ||J qdd + gamma - a*||_inf from constraint_kinematics.hpp
/// on the generated qdd, and its decrease with K.
void expectResidualIsTheConstraintResidual(const SolverUnderTest& solver, const System& sys);

}  // namespace proxgen::test

// Comparing a generated solver with the generic solvers it was generated from:
// the error measure and the conditioning-aware bounds, shared by
// `proxgen verify` (cli/verify.cpp) and the generated-solver tests
// (tests/generated/harness_lib.cpp), so what a user runs on their robot is
// what the project's tests check. The argument for the bounds is in compare.cpp.
#pragma once

#include <string>
#include <vector>

#include "algorithms/data.hpp"
#include "model/model.hpp"
#include "model/state.hpp"

namespace proxgen::verify {

/// max |a - b| / max(1, max |b|): relative to the size of the reference vector.
double relErr(const VecX& a, const VecX& b);

/// The state as a solver of that Scalar sees it (q, v, tau rounded to float
/// when `isFloat`), so the generic solver (in double) answers the same question.
State roundedToScalar(State s, bool isFloat);

/// What the bounds of one state need: the joint-space inertia, the constraint
/// Jacobian and their conditioning (computed once per state, for every mu and K).
struct Conditioning {
  bool isFloat = false;
  double eps = 0;     // unit round-off of the generated Scalar
  double floor = 0;   // smallest bound: 1e-12 in double, 64 u in float
  double safety = 0;  // c n, c = 10, n = nv + nc
  double kappaM = 1;  // condition number of M
  MatX M, J;
};
Conditioning conditioningAt(const System& sys, Data& scratch, const State& s, bool isFloat);

/// The bounds at one mu (every K): `primal` for constrainedABA's qdd, `dual`
/// for proxPV's qdd and lambda; constrainedABA's lambda also depends on the
/// answer (cabaLambdaBound).
struct Bounds {
  double primal = 0, dual = 0;
  double kappaC = 1;  // condition number of M + mu J^T J
  double mu = 0;
  double contraction = 0;  // 1 / (1 + mu g_min): how much of a step's error the next proximal step keeps
};
Bounds boundsAt(const Conditioning& c, double mu);
/// How many proximal steps' round-off K steps of proxPV carry at most:
/// (1 - rho^K) / (1 - rho), rho = b.contraction (K when rho = 1).
double proximalAccumulation(const Bounds& b, int K);
/// constrainedABA's lambda = mu (K a - k) multiplies the error of J qdd by mu.
double cabaLambdaBound(const System& sys, const Conditioning& c, const Bounds& b, const VecX& genericQdd,
                       const VecX& genericLambda);

/// The four results of one generated solve pair at one (state, mu, K).
struct GeneratedAnswer {
  VecX cabaQdd, cabaLambda, pvQdd, pvLambda;
};

/// One compared quantity: its error and the bound it must stay below.
struct Compared {
  const char* what;  // "constrained_aba qdd", ...
  double error, bound;
  bool finite;       // the generated and the generic values are all finite
};

/// Runs constrainedAba and proxPv at (s, mu, K) into `d` and compares `gen`
/// with them: constrained_aba qdd, constrained_aba lambda, prox_pv qdd, prox_pv lambda.
struct Comparison {
  Compared item[4];
};
Comparison compareWithGeneric(const System& sys, Data& d, const Conditioning& c, const Bounds& b, const State& s,
                              int K, const GeneratedAnswer& gen);

// ---- The dynamics library (docs/dynamics.md): each generated function the
// solver holds against its generic twin, one entry per function in
// compare.cpp's table (kLibrary), so a new function is a few lines there.

/// One state's inputs beyond (q, v) and what the generated functions returned;
/// an empty result means the solver does not hold that function.
struct LibraryAnswer {
  VecX qdd, lambda;  // inverse_dynamics' inputs (lambda: nc values)
  VecX tau;          // inverse_dynamics(q, v, qdd, lambda)
  VecX h;            // nonlinear_effects(q, v)
  MatX M, Minv;      // mass_matrix(q), mass_matrix_inverse(q)
};

/// max |gen - generic| / max(1, max |generic|) over the entries of a matrix.
double relErr(const MatX& a, const MatX& b);

/// The bound for torques tau = M qdd + h + J^T lambda computed by a recursion
/// without a solve (RNEA, or the residual of a backward-stable solve): c n u
/// times the size of the terms summed, |M| |qdd| + |J|^T |lambda| + |h| + |g| (+ |tau|),
/// relative to max(1, |tau|), floor included.
double torqueBound(const System& sys, Data& d, const Conditioning& c, const State& s, const VecX& qdd,
                   const VecX& lambda, const VecX& tau);

/// Every function `gen` holds against its generic twin at state s (q, v).
std::vector<Compared> compareLibraryWithGeneric(const System& sys, Data& d, const Conditioning& c, const State& s,
                                                const LibraryAnswer& gen);

// ---- The constraint functions (constraint_placements, constraint_jacobian,
// constraint_drift, delassus, delassus_inverse, constraint_wrenches) against their generic twins
// (algorithms/constraint_kinematics.hpp, algorithms/delassus.hpp); bounds
// argued in compare.cpp. A self-contained block.
struct ConstraintAnswer {
  // Row-major as the generated functions write them; an empty vector: not generated.
  VecX X, J, gamma, G, Ginv, W;
  double mu = 0;  // the s.mu delassus_inverse ran with
  VecX lambda;    // the nc multipliers constraint_wrenches ran with
};
/// One Compared per function present in `gen` (in the order above).
std::vector<Compared> compareConstraintFunctions(const System& sys, Data& d, const Conditioning& c, const State& s,
                                                 const ConstraintAnswer& gen);

// ---- The derivative functions (docs/derivatives.md) against
// algorithms/derivatives.cpp; bounds argued in compare.cpp. Row-major results
// as nv x nv / nc x nv matrices; an empty matrix: not generated.
struct DerivativeAnswer {
  VecX qdd, lambda, tau;  // the inputs: inverse_dynamics_derivatives' (qdd, lambda), the others' tau
  MatX dtau_dq, dtau_dv;  // inverse_dynamics_derivatives(q, v, qdd, lambda)
  VecX fQdd;              // forward_dynamics_derivatives(q, v, tau)
  MatX fDq, fDv, fDtau;
  VecX cQdd, cLambda;     // constrained_dynamics_derivatives(q, v, tau, Settings{mu, K})
  MatX cDq, cDv, cDtau, cLq, cLv, cLtau;
  double mu = 0;
  int K = 0;
};
/// One Compared per result present in `gen`.
std::vector<Compared> compareDerivatives(const System& sys, Data& d, const Conditioning& c, const State& s,
                                         const DerivativeAnswer& gen);

}  // namespace proxgen::verify

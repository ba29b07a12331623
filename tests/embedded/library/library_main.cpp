// Firmware main of fw_library_quadruped (docs/embedded.md, "The dynamics library on the
// target"): the whole dynamics library of the example quadruped (`proxgen generate ...
// --functions all`, written by the host build into inputs/quadruped/library/<scalar>/), in the
// firmware's scalar, checked on the target by identities between its entry points, at the
// states (q, v, tau) of vectors_quadruped.cpp. No reference values: each identity ties outputs
// of different recursions together, so a wrong term in one of them breaks it by O(1).
//
//   1. M Minv = I                    mass_matrix, mass_matrix_inverse
//   2. h = ID(q, v, 0, nullptr)      nonlinear_effects, inverse_dynamics
//   3. ID(q, v, qdd, lambda) = tau   inverse_dynamics at prox_pv's answer (layout mu and K)
//   3b.   the same at constrained_aba's answer (float: at mu = 100, see kMuPrimal)
//   4. (G + I/mu) Ginv = I           delassus, delassus_inverse
//   5. G = J Minv J^T                delassus, constraint_jacobian, mass_matrix_inverse
//   6. M dqdd/dx + J^T dlambda/dx = R1 (x = q, v, tau; R1 = -dtau/dq, -dtau/dv, I: the implicit
//      function theorem's first row)  constrained_dynamics_derivatives, inverse_dynamics_derivatives
//   7. J dqdd/dtau = (I + mu G)^-K J Minv ~ 0 (the contacts' acceleration does not move with
//      tau; double only, see there)  constrained_dynamics_derivatives, delassus_inverse
//
// Every identity has a bound argued below from u (the unit roundoff of the scalar: 2^-53 on the
// M7, 2^-24 on the M4F) and a condition number computed here from the library's own outputs
// (first order: the computed M, Minv, J are accurate to far better than the factor 10 of c).
// c = 10 and n = nv as the verification suites' round-off bounds (tests/numerics.hpp): every
// function is a short chain of backward-stable symmetric eliminations or sums of products.
// The firmware prints each worst error / bound over the states and exits 1 if any exceeds 1.
// (constraint_placements and constraint_drift have no identity here; they run at every state
// and their outputs must be finite, so they are linked, run without a fault and are counted.)
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "fw/io.hpp"
#include "fw/stack.hpp"
#include "fw/trace.hpp"
#include "proxgen_vectors.hpp"
#include "quadruped.hpp"

namespace {

namespace gen = quadruped;
using Scalar = gen::Scalar;
static_assert(std::is_same_v<Scalar, proxgen_vectors::Real>,
              "test vectors compiled for another scalar (PROXGEN_VECTORS_FLOAT)");

const proxgen_vectors::Case& tc = proxgen_vectors::test_case;
constexpr bool kFloat = std::is_same_v<Scalar, float>;
constexpr int nv = gen::nv, nc = gen::nc;
constexpr Scalar kU = std::numeric_limits<Scalar>::epsilon() / 2;  // unit roundoff
constexpr Scalar kC = 10;                                           // as tests/numerics.hpp
constexpr Scalar kN = Scalar(nv);

// mu of identity 4. delassus_inverse computes (G + I/mu)^-1 = mu I - mu^2 J A^-1 J^T,
// A = M + mu J^T J (its header): the two terms cancel, so its absolute error is about
// u kappa(A) mu, and the residual of (G + I/mu) Ginv grows like u kappa(A) mu ||G + I/mu||, i.e.
// like u mu^2 (kappa(A) grows with mu; measured on the target: the float residual is 5e-5 at
// mu = 1, 1.6e-3 at 10, 0.13 at 100 and 1e3 at 1e4, the double one 4e-6 at 1e4). Double checks
// at the layout's mu = 1e4 (bound ~0.09). In float at mu = 1e4 nothing is left to check, and
// at mu = 10 the bound below is ~7 (>= 1: it could not tell a wrong answer from a right one), so
// float uses mu = 1 (bound ~0.4): there mu ||G|| ~ 80 >> 1 still, so Ginv is the cancelling
// difference of the penalty recursion, not just mu I.
const Scalar kMuInverse = kFloat ? Scalar(1) : Scalar(1e4);

// mu of constrained_aba in 3b: the layout's in double; in float the largest mu that
// docs/embedded.md ("Float accuracy") advises for a float constrained_aba on this robot,
// 1.7e3 m = 108 (m = 0.064 kg, its lightest support body), rounded to 100.
const Scalar kMuPrimal = kFloat ? Scalar(100) : Scalar(1e4);

gen::Workspace g_w;  // static, so its size is known at link time
Scalar g_M[nv * nv], g_Minv[nv * nv], g_J[nc * nv], g_G[nc * nc], g_Ginv[nc * nc];
Scalar g_h[nv], g_id[nv], g_tau[nv], g_qdd[nv], g_lambda[nc], g_gamma[nc];
Scalar g_X[12 * gen::ncons];
Scalar g_d[nv];  // sqrt(diag M): the Jacobi scaling
Scalar g_dX[3][nv * nv], g_dL[3][nc * nv], g_dtau_dq[nv * nv], g_dtau_dv[nv * nv];  // 6 and 7
Scalar g_cqdd[nv], g_clambda[nc];

Scalar max_of(Scalar a, Scalar b) { return a < b ? b : a; }  // callers map NaN to infinity first

// err / bound, NaN or infinity when err is not finite (then the check fails).
Scalar ratio(Scalar err, Scalar bound) {
  if (!std::isfinite(err)) return std::numeric_limits<Scalar>::infinity();
  return err / bound;
}

void print_num(Scalar v) {
  if constexpr (kFloat)
    fw::print_float(v, 3);
  else
    fw::print_double(v, 3);
}

// ||A||_inf of a square n x n row-major matrix with entry (i, j) divided by s_i s_j (Jacobi
// scaling; s = nullptr: unscaled); inverse = true multiplies by s_i s_j instead (for an inverse).
Scalar norm_inf(const Scalar* A, int n, const Scalar* s, bool inverse) {
  Scalar best = 0;
  for (int i = 0; i < n; ++i) {
    Scalar row = 0;
    for (int j = 0; j < n; ++j) {
      Scalar x = std::fabs(A[i * n + j]);
      if (s) x = inverse ? x * s[i] * s[j] : x / (s[i] * s[j]);
      row += x;
    }
    best = max_of(best, row);
  }
  return best;
}

struct Check {
  const char* name;
  Scalar err = 0, bound = 0, worst = 0;  // at the state of the worst ratio
};
Check g_checks[8] = {{"M Minv = I"}, {"h = ID(q, v, 0)"}, {"ID(q, v, qdd, lambda) = tau (prox_pv)"},
                     {"(G + I/mu) Ginv = I"}, {"G = J Minv J^T"},
                     {"ID(q, v, qdd, lambda) = tau (constrained_aba)"},
                     {"M dqdd/dx + J^T dlambda/dx = R1 (derivatives)"},
                     {"J dqdd/dtau = (I + mu G)^-K J Minv (derivatives)"}};
constexpr int kChecks = 8;

void record(int k, Scalar err, Scalar bound) {
  Check& c = g_checks[k];
  const Scalar r = ratio(err, bound);
  if (std::isnan(c.worst)) return;        // a NaN ratio stays (it fails the check)
  if (c.bound == 0 || !(r <= c.worst)) {  // the first state, a larger ratio, or NaN
    c.err = err;
    c.bound = bound;
    c.worst = r;
  }
}

void run_state(int s) {
  const Scalar* q = tc.q + s * tc.nq;
  const Scalar* v = tc.v + s * tc.nv;
  const Scalar* tau = tc.tau + s * tc.nv;
  gen::Settings settings;  // the layout's mu and K
  const bool trace = s == 0;  // instruction counts per entry point (count_insns.py), state 0

  // Region order: mass_matrix, mass_matrix_inverse, nonlinear_effects, inverse_dynamics,
  // prox_pv, inverse_dynamics, constraint_jacobian, delassus, delassus_inverse,
  // constrained_aba, inverse_dynamics, constrained_dynamics_derivatives,
  // inverse_dynamics_derivatives, constraint_placements, constraint_drift.
  if (trace) fw::trace_begin();
  gen::mass_matrix(q, g_w, g_M);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::mass_matrix_inverse(q, g_w, g_Minv);
  if (trace) fw::trace_end();

  // ---- 1. M Minv = I, Jacobi-scaled: Ms = D^-1 M D^-1, Ms^-1 = D Minv D, D = sqrt(diag M).
  // Minv comes from a recursion that is a symmetric elimination of M in tree order, whose
  // error bound, like Cholesky's, does not change under diagonal scaling (van der Sluis): the
  // scaled residual D^-1 (M Minv - I) D = Ms Ms^-1 - I is within c n u kappa(Ms) (the inverse's
  // error) + n u kappa(Ms) (the product's). kappa(Ms) = ||Ms||_inf ||Ms^-1||_inf from the
  // outputs. (Unscaled, the 9 kg trunk and the 64 g shanks would make the bound far looser.)
  for (int i = 0; i < nv; ++i) g_d[i] = std::sqrt(g_M[i * nv + i]);
  const Scalar kappa_M = norm_inf(g_M, nv, g_d, false) * norm_inf(g_Minv, nv, g_d, true);
  {
    Scalar err = 0;
    for (int i = 0; i < nv; ++i)
      for (int j = 0; j < nv; ++j) {
        Scalar x = 0;
        for (int k = 0; k < nv; ++k) x += g_M[i * nv + k] * g_Minv[k * nv + j];
        x = x * g_d[j] / g_d[i] - (i == j ? Scalar(1) : Scalar(0));
        err = max_of(err, std::isfinite(x) ? std::fabs(x) : std::numeric_limits<Scalar>::infinity());
      }
    record(0, err, (kC + 1) * kN * kU * kappa_M);
  }

  // ---- 2. nonlinear_effects = inverse_dynamics at qdd = 0 without constraint forces: the same
  // recursion (RNEA) with the qdd terms dropped, so the two differ by the order of operations
  // only. RNEA is sums of products over a chain of at most 5 bodies (trunk to foot), each body a
  // few dozen operations; the forward error of each torque is within c n u of the sum of the
  // magnitudes of its terms, which for this robot is of the size of max|h| (gravity dominates,
  // no cancellation beyond it). Bound: c n u max|h| (absolute).
  Scalar zero[nv] = {};
  if (trace) fw::trace_begin();
  gen::nonlinear_effects(q, v, g_w, g_h);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::inverse_dynamics(q, v, zero, nullptr, g_w, g_id);
  if (trace) fw::trace_end();
  {
    Scalar err = 0, hmax = 0;
    for (int i = 0; i < nv; ++i) {
      err = max_of(err, std::isfinite(g_h[i] - g_id[i]) ? std::fabs(g_h[i] - g_id[i])
                                                         : std::numeric_limits<Scalar>::infinity());
      hmax = max_of(hmax, std::fabs(g_h[i]));
    }
    record(1, err, kC * kN * kU * hmax);
  }

  // ---- 3. inverse_dynamics(q, v, qdd, lambda) = tau at prox_pv's (qdd, lambda): proxPV
  // returns qdd^K = qdd_free - M^-1 J^T lambda^K with its returned lambda^K
  // (docs/algorithms.md, the dual iteration), so M qdd + h + J^T lambda = tau in exact
  // arithmetic at any K, with no multiplier update after qdd (no factor mu on round-off). Its
  // two solves with M are backward stable, so each row of the residual is within c n u of the
  // magnitudes of its terms (componentwise backward error). Error: max_i |r_i| / scale_i,
  // scale_i = (|M||qdd|)_i + |h_i| + (|J^T||lambda|)_i + |tau_i|; bound: c n u.
  if (trace) fw::trace_begin();
  gen::prox_pv(q, v, tau, settings, g_w, g_qdd, g_lambda);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::inverse_dynamics(q, v, g_qdd, g_lambda, g_w, g_tau);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::constraint_jacobian(q, g_w, g_J);
  if (trace) fw::trace_end();
  {
    Scalar err = 0;
    for (int i = 0; i < nv; ++i) {
      Scalar scale = std::fabs(g_h[i]) + std::fabs(tau[i]);
      for (int k = 0; k < nv; ++k) scale += std::fabs(g_M[i * nv + k] * g_qdd[k]);
      for (int r = 0; r < nc; ++r)
        scale += std::fabs(g_J[r * nv + i] * g_lambda[r]);
      const Scalar e = std::fabs(g_tau[i] - tau[i]) / scale;
      err = max_of(err, std::isfinite(e) ? e : std::numeric_limits<Scalar>::infinity());
    }
    record(2, err, kC * kN * kU);
  }

  // ---- 4. (G + I/mu) Ginv = I at kMuInverse (see there). Bound, from the header's estimate
  // of delassus_inverse's absolute error u kappa(A) mu (A = M + mu J^T J) times the norm of
  // what multiplies it: c n u kappa(A) mu ||G + I/mu||_inf. kappa(A) as in 1, Jacobi-scaled
  // (the recursion is an elimination of A), bounded from the outputs without inverting A:
  // A >= M, so A^-1 <= M^-1 and ||D_A A^-1 D_A||_2 <= ||D_A Minv D_A||_2, and for a symmetric
  // matrix ||.||_2 <= ||.||_inf: kappa_2(A_s) <= ||A_s||_inf ||D_A Minv D_A||_inf,
  // D_A = sqrt(diag A).
  if (trace) fw::trace_begin();
  gen::delassus(q, g_w, g_G);
  if (trace) fw::trace_end();
  gen::Settings inv;
  inv.mu = kMuInverse;
  if (trace) fw::trace_begin();
  gen::delassus_inverse(q, inv, g_w, g_Ginv);
  if (trace) fw::trace_end();
  {
    const Scalar mu = kMuInverse;
    Scalar A[nv * nv], dA[nv];
    for (int i = 0; i < nv; ++i)
      for (int j = 0; j < nv; ++j) {
        Scalar x = 0;
        for (int r = 0; r < nc; ++r) x += g_J[r * nv + i] * g_J[r * nv + j];
        A[i * nv + j] = g_M[i * nv + j] + mu * x;
      }
    for (int i = 0; i < nv; ++i) dA[i] = std::sqrt(A[i * nv + i]);
    const Scalar kappa_A = norm_inf(A, nv, dA, false) * norm_inf(g_Minv, nv, dA, true);
    Scalar GI[nc * nc];
    for (int i = 0; i < nc * nc; ++i) GI[i] = g_G[i] + (i % (nc + 1) == 0 ? 1 / mu : Scalar(0));
    Scalar err = 0;
    for (int i = 0; i < nc; ++i)
      for (int j = 0; j < nc; ++j) {
        Scalar x = 0;
        for (int k = 0; k < nc; ++k) x += GI[i * nc + k] * g_Ginv[k * nc + j];
        x -= (i == j ? Scalar(1) : Scalar(0));
        err = max_of(err, std::isfinite(x) ? std::fabs(x) : std::numeric_limits<Scalar>::infinity());
      }
    record(3, err, kC * kN * kU * kappa_A * mu * norm_inf(GI, nc, nullptr, false));
  }

  // ---- 5. G = J Minv J^T. Both sides carry the error of a recursion on M: Minv's, as in 1,
  // |D dMinv D| within c n u kappa(Ms) ||Ms^-1||, i.e. |dMinv_kl| <= c n u kappa(Ms)
  // ||Ms^-1||_inf / (d_k d_l), which J Minv J^T turns into c n u kappa(Ms) S with
  // S = ||Ms^-1||_inf (max_r sum_k |J_rk| / d_k)^2; delassus's G is the same class of
  // recursion (the apparent inverse inertias, Minv projected on the constraint rows) and the
  // products add n u S. Error: max |G - J Minv J^T| / S; bound: (2 c + 1) n u kappa(Ms).
  {
    Scalar jd = 0;
    for (int r = 0; r < nc; ++r) {
      Scalar row = 0;
      for (int k = 0; k < nv; ++k) row += std::fabs(g_J[r * nv + k]) / g_d[k];
      jd = max_of(jd, row);
    }
    const Scalar S = norm_inf(g_Minv, nv, g_d, true) * jd * jd;
    Scalar err = 0;
    for (int i = 0; i < nc; ++i)
      for (int j = 0; j < nc; ++j) {
        Scalar x = 0;
        for (int k = 0; k < nv; ++k) {
          Scalar y = 0;
          for (int l = 0; l < nv; ++l) y += g_Minv[k * nv + l] * g_J[j * nv + l];
          x += g_J[i * nv + k] * y;
        }
        const Scalar e = std::fabs(g_G[i * nc + j] - x) / S;
        err = max_of(err, std::isfinite(e) ? e : std::numeric_limits<Scalar>::infinity());
      }
    record(4, err, (2 * kC + 1) * kN * kU * kappa_M);
  }

  // ---- 3b. As 3 at constrained_aba's (qdd, lambda): it solves
  // (M + mu J^T J) qdd = tau - h - J^T (lambda' + mu (gamma - a*)), then updates
  // lambda = lambda' + mu (J qdd + gamma - a*) (docs/algorithms.md, the primal iteration), so
  // M qdd + h + J^T lambda = tau in exact arithmetic too. Its elimination is of M + mu J^T J,
  // whose backward error is relative to |M| + mu |J^T||J| (the light shanks keep their own
  // inertia only to u mu / m: part of that backward error), and the update after the solve
  // multiplies the round-off of J qdd by mu: both are the term mu (|J^T||J||qdd|)_i added to
  // the scale of 3. Bound: c n u. That term dominates the scale (measured: a relative change d
  // of one qdd entry shows as an error of ~d / 4e4 at mu = 1e4, ~d / 400 at mu = 100), so in
  // float (bound 1e-5) at mu = 1e4 a 1 % error in qdd would stay inside the bound: float runs
  // constrained_aba at kMuPrimal instead (there a 1 % change of qdd[9] fails the check).
  gen::Settings caba = settings;
  caba.mu = kMuPrimal;
  if (trace) fw::trace_begin();
  gen::constrained_aba(q, v, tau, caba, g_w, g_qdd, g_lambda);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::inverse_dynamics(q, v, g_qdd, g_lambda, g_w, g_tau);
  if (trace) fw::trace_end();
  {
    Scalar Jqdd[nc];  // (|J||qdd|)_r
    for (int r = 0; r < nc; ++r) {
      Jqdd[r] = 0;
      for (int k = 0; k < nv; ++k) Jqdd[r] += std::fabs(g_J[r * nv + k] * g_qdd[k]);
    }
    Scalar err = 0;
    for (int i = 0; i < nv; ++i) {
      Scalar scale = std::fabs(g_h[i]) + std::fabs(tau[i]);
      for (int k = 0; k < nv; ++k) scale += std::fabs(g_M[i * nv + k] * g_qdd[k]);
      for (int r = 0; r < nc; ++r)
        scale += std::fabs(g_J[r * nv + i]) * (std::fabs(g_lambda[r]) + caba.mu * Jqdd[r]);
      const Scalar e = std::fabs(g_tau[i] - tau[i]) / scale;
      err = max_of(err, std::isfinite(e) ? e : std::numeric_limits<Scalar>::infinity());
    }
    record(5, err, kC * kN * kU);
  }

  // ---- 6. constrained_dynamics_derivatives (the layout's mu and K) against the implicit
  // function theorem's first row, M X + J^T L = R1 with R1 = -dtau/dq, -dtau/dv, I for
  // x = q, v, tau (dtau/dx from inverse_dynamics_derivatives at its (qdd, lambda)). The
  // function computes X = Minv (R1 - J^T L) with its own Minv, so for ANY L the identity holds
  // up to Minv's error and the products' round-off: with Y = R1 - J^T L, the Jacobi-scaled
  // residual column D^-1 (M X - Y) e_j = Ms Es (D^-1 Y e_j), where Ms Es is the scaled
  // residual of the inverse, within (c + 1) n u kappa(Ms) as in 1; the products X = Minv Y,
  // J^T L and M X add c n u kappa(Ms) more. Error: max_j ||D^-1 R e_j||_inf / ||D^-1 Y e_j||_inf;
  // bound: (2 c + 1) n u kappa(Ms). (It does not test L: 7 does.)
  if (trace) fw::trace_begin();
  gen::constrained_dynamics_derivatives(q, v, tau, settings, g_w, g_cqdd, g_clambda, g_dX[0], g_dX[1], g_dX[2],
                                        g_dL[0], g_dL[1], g_dL[2]);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::inverse_dynamics_derivatives(q, v, g_cqdd, g_clambda, g_w, g_dtau_dq, g_dtau_dv);
  if (trace) fw::trace_end();
  {
    Scalar err = 0;
    for (int b = 0; b < 3; ++b)
      for (int j = 0; j < nv; ++j) {
        Scalar res = 0, ys = 0;
        for (int i = 0; i < nv; ++i) {
          Scalar y = b == 2 ? (i == j ? Scalar(1) : Scalar(0)) : -(b == 0 ? g_dtau_dq : g_dtau_dv)[i * nv + j];
          for (int r = 0; r < nc; ++r) y -= g_J[r * nv + i] * g_dL[b][r * nv + j];
          Scalar mx = 0;
          for (int k = 0; k < nv; ++k) mx += g_M[i * nv + k] * g_dX[b][k * nv + j];
          const Scalar e = std::fabs(mx - y) / g_d[i];
          res = max_of(res, std::isfinite(e) ? e : std::numeric_limits<Scalar>::infinity());
          ys = max_of(ys, std::fabs(y) / g_d[i]);
        }
        err = max_of(err, res / ys);
      }
    record(6, err, (2 * kC + 1) * kN * kU * kappa_M);
  }

  // ---- 7. J X_tau, X_tau = dqdd/dtau: with S_K the K proximal steps as one operator,
  // X_tau = Minv - Minv J^T S_K J Minv and G S_K = I - (I + mu G)^-K (the steps telescope), so
  // J X_tau = (I + mu G)^-K J Minv: zero but for the proximal truncation, whose factor is below
  // rho^K, rho = ||(I + mu G)^-1||_2 <= ||(G + I/mu)^-1||_inf / mu (delassus_inverse at the
  // layout's mu, 4). This is what tests L: a wrong L leaves J Minv, O(1). Round-off: J X_tau is
  // the difference J Minv - G L, whose terms are of the size of J Minv; L comes from solves with
  // A = G + I/mu (error u kappa(A) relative, kappa(A) <= 1 + mu ||G||_inf since A >= I/mu), and
  // G A^-1 <= I keeps that error at the size of J Minv; Minv's error adds c n u kappa(Ms).
  // Error: max |J X_tau| / max |J Minv|; bound: c n u (kappa(A) + kappa(Ms)) + nc rho^K (nc:
  // the 2-norm against the entries). In float at mu = 1e4, kappa(A) ~ 1e5 makes the bound
  // exceed 1 (nothing could fail): float skips 7 (6 still runs).
  if constexpr (!kFloat) {
    Scalar jx = 0, jm = 0;
    for (int r = 0; r < nc; ++r)
      for (int j = 0; j < nv; ++j) {
        Scalar a = 0, b = 0;
        for (int k = 0; k < nv; ++k) {
          a += g_J[r * nv + k] * g_dX[2][k * nv + j];
          b += g_J[r * nv + k] * g_Minv[k * nv + j];
        }
        jx = max_of(jx, std::isfinite(a) ? std::fabs(a) : std::numeric_limits<Scalar>::infinity());
        jm = max_of(jm, std::fabs(b));
      }
    // rho reads Ginv of 4, computed at kMuInverse: in double that is the layout's mu (else
    // the check fails: an infinite error).
    const Scalar mu = settings.mu;
    const Scalar rho = mu == kMuInverse ? norm_inf(g_Ginv, nc, nullptr, false) / mu
                                        : std::numeric_limits<Scalar>::infinity();
    Scalar trunc = 1;
    for (int k = 0; k < settings.iterations; ++k) trunc *= rho;
    const Scalar kappa_A = 1 + mu * norm_inf(g_G, nc, nullptr, false);
    record(7, jx / jm, kC * kN * kU * (kappa_A + kappa_M) + Scalar(nc) * trunc);
  }

  // The two constraint functions without an identity here: run, finite.
  if (trace) fw::trace_begin();
  gen::constraint_placements(q, g_w, g_X);
  if (trace) fw::trace_end();
  if (trace) fw::trace_begin();
  gen::constraint_drift(q, v, g_w, g_gamma);
  if (trace) fw::trace_end();
}

bool all_finite(const Scalar* x, int n) {
  for (int k = 0; k < n; ++k)
    if (!std::isfinite(x[k])) return false;
  return true;
}

}  // namespace

int main() {
  fw::print("library quadruped: cpu=");
  fw::print(fw::cpu_name());
  fw::print(kFloat ? " scalar=float" : " scalar=double");
  fw::print(" nq ");
  fw::print_int(gen::nq);
  fw::print(" nv ");
  fw::print_int(nv);
  fw::print(" nc ");
  fw::print_int(nc);
  fw::print("\nworkspace: ");
  fw::print_int(static_cast<long long>(sizeof(gen::Workspace)));
  fw::print(" bytes; states ");
  fw::print_int(tc.num_states);
  fw::print("; mu of (G + I/mu) Ginv: ");
  print_num(kMuInverse);
  fw::print("; mu of constrained_aba: ");
  print_num(kMuPrimal);
  fw::print("\n");
  if (tc.nq != gen::nq || tc.nv != nv || tc.nc != nc) {
    fw::print("FAILED: the test vectors do not fit this library (nq, nv or nc)\n");
    return 1;
  }

  int failures = 0;
  for (int s = 0; s < tc.num_states; ++s) {
    run_state(s);
    if (!all_finite(g_X, 12 * gen::ncons) || !all_finite(g_gamma, nc)) {
      fw::print("FAILED: constraint_placements or constraint_drift not finite at state ");
      fw::print_int(s);
      fw::print("\n");
      ++failures;
    }
  }
  for (int k = 0; k < kChecks; ++k) {
    const Check& c = g_checks[k];
    if (kFloat && k == 7) continue;  // not run in float (see 7)
    fw::print("max ");
    fw::print(c.name);
    fw::print(": error ");
    print_num(c.err);
    fw::print(" bound ");
    print_num(c.bound);
    fw::print(" error/bound ");
    print_num(c.worst);
    const bool ok = c.worst <= 1;  // false for NaN
    fw::print(ok ? " ok\n" : " FAILED\n");
    if (!ok) ++failures;
  }

  if (!fw::report_stack()) ++failures;  // the whole firmware's stack against its budget
  fw::print(failures == 0 ? "library test: PASS\n" : "library test: FAIL\n");
  return failures == 0 ? 0 : 1;
}

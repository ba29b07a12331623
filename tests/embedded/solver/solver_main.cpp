// Firmware main of the generated-solver tests (docs/embedded.md, "Generated solvers on the
// target"): runs one generated solver, in the firmware's scalar, on the states of its test
// vectors and compares qdd and lambda with the generic solvers' double answers from the host.
// Built once per case and scalar by tests/embedded/CMakeLists.txt with
//   PROXGEN_SOLVER_HEADER "NAME.hpp", PROXGEN_SOLVER_NAMESPACE NAME, PROXGEN_VECTORS_FLOAT 0|1.
// Exit status 0 when every checked answer is within its tolerance.
//
// Error measure (as the host tests' test::relErr): max|x - x_ref| / max(1, max|x_ref|), the
// reference being the generic solver of the same algorithm, in double on the host.
// Tolerance = (round-off of the reference) + (round-off of the solver under test):
//  - reference: eps_double * (primal + dual), the verification suites' bound for the generic
//    solvers (tests/numerics.hpp, roundoffBounds: c n kappa of M + mu J^T J, of M and of G),
//    computed by the host per state and mu. Worst-case (c n), it matters only in double; it
//    covers the generic constrainedAba's own round-off, which is the larger one on some states.
//  - solver: kSafety * u * (kappa_s(M) + kappa_s(G) + mu / m), u the unit roundoff of the
//    firmware's scalar (this term decides the float tolerance):
//      kappa_s(M) + kappa_s(G), Jacobi-scaled (host): the eliminations with M and with
//        G = J M^-1 J^T (+ I/mu) that both algorithms make, backward stable;
//      mu / m, m the lightest body on the constraint support: constrainedABA adds the penalty
//        mu K^T K (mu is a mass) to the inertia of every support body, which then keeps its own
//        inertia only to a relative u mu / m, and the multiplier update mu (K a - k) multiplies
//        the absolute round-off of the constraint acceleration by mu. kappa misses this when
//        M + mu J^T J is well scaled (a fully welded arm); it is also the criterion of the
//        float warning of `proxgen check`.
//    kSafety = 50: in float (where the reference's error is negligible) the largest measured
//    ratio of error to u * (kappa + mu / m), over all twelve cases, 3 states, mu = 1e2..1e6,
//    K = 3 and 100 and both algorithms, was 9.8 over the checked answers and 17.7 over all
//    finite ones (docs/embedded.md). In double the measured
//    error can exceed this estimate (117 times on solo_f3x4 at mu = 1e5) because there the
//    generic constrainedAba is the less accurate side: the reference term covers it.
// A wrong term in a solver gives errors of order 1. A tolerance of 1 or more cannot tell a
// right answer from a wrong one: such answers are printed as "not-checked" (float, at
// u * mu / m of 0.02 or more: large mu on light bodies).
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include PROXGEN_SOLVER_HEADER
#include "fw/io.hpp"
#include "fw/stack.hpp"
#include "proxgen_vectors.hpp"

namespace {

namespace gen = PROXGEN_SOLVER_NAMESPACE;
using proxgen_vectors::Algorithm;
using proxgen_vectors::Result;
using Scalar = gen::Scalar;
static_assert(std::is_same_v<Scalar, proxgen_vectors::Real>,
              "test vectors compiled for another scalar (PROXGEN_VECTORS_FLOAT)");

const proxgen_vectors::Case& tc = proxgen_vectors::test_case;
constexpr bool kFloat = std::is_same_v<Scalar, float>;
constexpr Scalar kUnitRoundoff = std::numeric_limits<Scalar>::epsilon() / 2;
constexpr Scalar kDoubleEps = Scalar(std::numeric_limits<double>::epsilon());
constexpr Scalar kSafety = 50;
constexpr int kMaxPerState = 64;  // results per state: mu values x K values x 2 algorithms

gen::Workspace g_workspace;  // static, so its size is known at link time
Scalar g_qdd[gen::nv];
Scalar g_lambda[gen::nc > 0 ? gen::nc : 1];

// Largest errors over the states, per (algorithm, mu, K).
struct Summary {
  Scalar qdd = 0, lambda = 0, tol = 0, estimate = 0, ratio = 0, mass_estimate = 0;
  bool unchecked = false, failed = false;
};
Summary g_summary[kMaxPerState];

void print_num(Scalar v) {
  if constexpr (kFloat)
    fw::print_float(v, 3);
  else
    fw::print_double(v, 3);
}

Scalar max_of(Scalar a, Scalar b) { return a < b ? b : a; }

// max|a - ref| / max(1, max|ref|); a non-finite answer is an infinite error.
Scalar rel_err(const Scalar* a, const Scalar* ref, int n) {
  Scalar num = 0, den = 1;
  for (int k = 0; k < n; ++k) {
    if (!std::isfinite(a[k])) return std::numeric_limits<Scalar>::infinity();
    num = max_of(num, std::fabs(a[k] - ref[k]));
    den = max_of(den, std::fabs(ref[k]));
  }
  return num / den;
}

const char* algorithm_name(Algorithm a) {
  return a == Algorithm::constrained_aba ? "constrained_aba" : "prox_pv";
}

void solve(const Result& r) {
  const Scalar* q = tc.q + r.state * tc.nq;
  const Scalar* v = tc.v + r.state * tc.nv;
  const Scalar* tau = tc.tau + r.state * tc.nv;
  gen::Settings s;
  s.mu = r.mu;
  s.iterations = r.iterations;
  if (r.algorithm == Algorithm::constrained_aba)
    gen::constrained_aba(q, v, tau, s, g_workspace, g_qdd, g_lambda);
  else
    gen::prox_pv(q, v, tau, s, g_workspace, g_qdd, g_lambda);
}

void print_result_head(const Result& r) {
  fw::print(algorithm_name(r.algorithm));
  fw::print(" mu ");
  print_num(r.mu);
  fw::print(" K ");
  fw::print_int(r.iterations);
}

// Runs one result, folds it into its summary; returns false when it is out of tolerance.
bool check(const Result& r, Summary& sum) {
  solve(r);
  const Scalar eq = rel_err(g_qdd, r.qdd, tc.nv);
  const Scalar el = rel_err(g_lambda, r.lambda, tc.nc);
  const Scalar mass_estimate = kUnitRoundoff * r.mu / tc.light_mass;
  const Scalar estimate = kUnitRoundoff * r.conditioning + mass_estimate;
  const Scalar tol = kDoubleEps * r.reference + kSafety * estimate;
  const Scalar err = max_of(eq, el);
  sum.qdd = max_of(sum.qdd, eq);
  sum.lambda = max_of(sum.lambda, el);
  sum.tol = max_of(sum.tol, tol);
  sum.estimate = max_of(sum.estimate, estimate);
  sum.ratio = max_of(sum.ratio, err / estimate);
  sum.mass_estimate = mass_estimate;
  if (tol >= 1) {
    sum.unchecked = true;
    return true;
  }
  if (err <= tol) return true;  // false for NaN too
  sum.failed = true;
  fw::print("FAILED: state ");
  fw::print_int(r.state);
  fw::print(" ");
  print_result_head(r);
  fw::print(": qdd error ");
  print_num(eq);
  fw::print(", lambda error ");
  print_num(el);
  fw::print(", tolerance ");
  print_num(tol);
  fw::print("\n");
  return false;
}

void print_summary(const Result& r, const Summary& s) {
  fw::print("max ");
  print_result_head(r);
  fw::print(": qdd ");
  print_num(s.qdd);
  fw::print(" lambda ");
  print_num(s.lambda);
  fw::print(" tol ");
  print_num(s.tol);
  fw::print(" estimate ");
  print_num(s.estimate);
  fw::print(" err/estimate ");
  print_num(s.ratio);
  fw::print(" u*mu/m ");
  print_num(s.mass_estimate);
  fw::print(s.failed ? " FAILED\n" : s.unchecked ? " not-checked\n" : " ok\n");
}

bool shapes_match() {
  if (tc.nq == gen::nq && tc.nv == gen::nv && tc.nc == gen::nc && tc.num_results % tc.num_states == 0 &&
      tc.num_results / tc.num_states <= kMaxPerState)
    return true;
  fw::print("FAILED: the test vectors do not fit this solver (nq, nv, nc or count)\n");
  return false;
}

}  // namespace

int main() {
  fw::print("solver ");
  fw::print(tc.name);
  fw::print(": cpu=");
  fw::print(fw::cpu_name());
  fw::print(kFloat ? " scalar=float" : " scalar=double");
  fw::print(" nq ");
  fw::print_int(gen::nq);
  fw::print(" nv ");
  fw::print_int(gen::nv);
  fw::print(" nc ");
  fw::print_int(gen::nc);
  fw::print("\nworkspace: ");
  fw::print_int(static_cast<long long>(sizeof(gen::Workspace)));
  fw::print(" bytes\nlightest support body: ");
  fw::print(tc.light_link);
  fw::print(" ");
  print_num(tc.light_mass);
  fw::print(" kg; layout mu ");
  print_num(tc.mu);
  fw::print("\n");
  if (!shapes_match()) return 1;

  int failures = 0;
  const int per_state = tc.num_results / tc.num_states;
  for (int k = 0; k < tc.num_results; ++k)
    if (!check(tc.results[k], g_summary[k % per_state])) ++failures;
  for (int k = 0; k < per_state; ++k) print_summary(tc.results[k], g_summary[k]);

  if (!fw::report_stack()) ++failures;  // the whole firmware's stack against its budget
  fw::print("results: ");
  fw::print_int(tc.num_results);
  fw::print(", failed: ");
  fw::print_int(failures);
  fw::print(failures == 0 ? "\nsolver test: PASS\n" : "\nsolver test: FAIL\n");
  return failures == 0 ? 0 : 1;
}

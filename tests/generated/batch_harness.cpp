// The batched solvers (generate --batch W, docs/batch.md) against the scalar
// generated solver of the same files, lane by lane. Built per solver by
// proxgen_test_batch_solver (CMakeLists.txt): PROXGEN_SOLVER_NAMESPACE names it.
//
// The bound is zero: bit for bit (NaN for NaN). Each lane runs the scalar
// solver's statements in the same order (the batched source is the scalar
// source's text over proxgen_rt::lanes), and every lane operation is the
// scalar IEEE operation (+ - * / sqrt correctly rounded per lane, selects and
// signs as bit operations, sincos the scalar kernel's operations and the C
// library beyond its range, log6 the scalar function per lane:
// tests/runtime/lanes_checks.inc checks each bit for bit). What could make a
// lane differ is a compiler contracting a * b + c into one fused operation in
// one of the two and not the other; these solvers are compiled with
// -ffp-contract=off (CMakeLists.txt), so none does (docs/batch.md, "Lane by lane").
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include PROXGEN_BATCH_HEADER

namespace {

namespace g = PROXGEN_SOLVER_NAMESPACE;
using S = g::Scalar;
constexpr int W = g::batch_width;

bool sameBits(S a, S b) {
  if (std::isnan(a) && std::isnan(b)) return true;
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// One state in the plain layout.
struct State {
  std::vector<S> q, v, tau, lambda0;
};

// Random states, and the hostile ones the lanes must keep apart: zero
// velocity and torque, angles past the sine kernel's range (1e6 rad), the
// zero configuration (singular for the arms: aligned axes), huge velocities,
// and a NaN configuration (NaN in its lane only).
std::vector<State> states(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<State> out;
  for (int k = 0; k < n; ++k) {
    State s{std::vector<S>(g::nq), std::vector<S>(g::nv), std::vector<S>(g::nv), std::vector<S>(g::nc)};
    for (S& x : s.q) x = S(3 * u(rng));
    for (S& x : s.v) x = S(2 * u(rng));
    for (S& x : s.tau) x = S(10 * u(rng));
    for (S& x : s.lambda0) x = S(5 * u(rng));
    switch (k % 6) {
      case 1:
        for (S& x : s.v) x = S(0);
        for (S& x : s.tau) x = S(0);
        break;
      case 2:
        for (S& x : s.q) x += S(1e6);
        break;
      case 3:
        for (S& x : s.q) x = S(0);
        break;
      case 4:
        for (S& x : s.v) x *= S(1e3);
        break;
      case 5:
        if (k == 5) s.q[std::size_t(g::nq - 1)] = std::numeric_limits<S>::quiet_NaN();  // a joint angle
        break;
      default:
        break;
    }
    out.push_back(s);
  }
  return out;
}

using ScalarSolve = void (*)(const S*, const S*, const S*, const g::Settings&, g::Workspace&, S*, S*) noexcept;
using BatchSolve = void (*)(const S*, const S*, const S*, const g::Settings&, g::BatchWorkspace&, S*, S*) noexcept;
using ManySolve = void (*)(int, const S*, const S*, const S*, const g::Settings&, g::BatchWorkspace&, S*, S*) noexcept;

struct Answer {
  std::vector<S> qdd, lambda;
};

Answer scalarAnswer(ScalarSolve solve, const State& s, g::Settings settings, bool warm, g::Workspace& w) {
  Answer a{std::vector<S>(g::nv), std::vector<S>(g::nc + 1)};
  settings.lambda0 = warm ? s.lambda0.data() : nullptr;
  solve(s.q.data(), s.v.data(), s.tau.data(), settings, w, a.qdd.data(), a.lambda.data());
  return a;
}

void expectLane(const Answer& expected, const std::vector<S>& qdd, const std::vector<S>& lambda, int at, int stride,
                const char* what) {
  for (int i = 0; i < g::nv; ++i)
    EXPECT_TRUE(sameBits(qdd[std::size_t(i * stride + at)], expected.qdd[std::size_t(i)]))
        << what << " qdd[" << i << "] of state " << at << ": " << qdd[std::size_t(i * stride + at)] << " vs "
        << expected.qdd[std::size_t(i)];
  for (int r = 0; r < g::nc; ++r)
    EXPECT_TRUE(sameBits(lambda[std::size_t(r * stride + at)], expected.lambda[std::size_t(r)]))
        << what << " lambda[" << r << "] of state " << at;
}

// W states lane-interleaved through the _batch kernel: each lane is the
// scalar solver on its state, at K = 0, 1, 3, with and without a warm start.
void checkBatch(ScalarSolve scalar, BatchSolve batch, const char* what) {
  static g::Workspace w;
  static g::BatchWorkspace bw;
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    const std::vector<State> st = states(W, seed);
    std::vector<S> q(std::size_t(g::nq * W)), v(std::size_t(g::nv * W)), tau(std::size_t(g::nv * W)),
        lambda0(std::size_t(g::nc * W + 1));
    for (int l = 0; l < W; ++l) {
      for (int i = 0; i < g::nq; ++i) q[std::size_t(i * W + l)] = st[std::size_t(l)].q[std::size_t(i)];
      for (int i = 0; i < g::nv; ++i) v[std::size_t(i * W + l)] = st[std::size_t(l)].v[std::size_t(i)];
      for (int i = 0; i < g::nv; ++i) tau[std::size_t(i * W + l)] = st[std::size_t(l)].tau[std::size_t(i)];
      for (int r = 0; r < g::nc; ++r) lambda0[std::size_t(r * W + l)] = st[std::size_t(l)].lambda0[std::size_t(r)];
    }
    for (int K : {0, 1, 3})
      for (bool warm : {false, true}) {
        g::Settings s;
        s.iterations = K;
        s.lambda0 = warm ? lambda0.data() : nullptr;
        std::vector<S> qdd(std::size_t(g::nv * W)), lambda(std::size_t(g::nc * W + 1));
        batch(q.data(), v.data(), tau.data(), s, bw, qdd.data(), lambda.data());
        std::vector<S> residuals(static_cast<std::size_t>(W));
        g::residual_batch(bw, residuals.data());
        for (int l = 0; l < W; ++l) {
          const Answer a = scalarAnswer(scalar, st[std::size_t(l)], s, warm, w);
          expectLane(a, qdd, lambda, l, W, what);
          EXPECT_TRUE(sameBits(residuals[std::size_t(l)], g::residual(w))) << what << " residual of lane " << l;
        }
      }
  }
}

// n states in the plain layout through _many, n a multiple of W, not one, and
// fewer than W: every state the scalar answer, nothing written past n.
void checkMany(ScalarSolve scalar, ManySolve many, const char* what) {
  static g::Workspace w;
  static g::BatchWorkspace bw;
  for (int n : {1, W - 1, W, 2 * W + 3}) {
    if (n < 1) continue;
    const std::vector<State> st = states(n, 7u + unsigned(n));
    std::vector<S> q, v, tau, lambda0;
    for (const State& s : st) {
      q.insert(q.end(), s.q.begin(), s.q.end());
      v.insert(v.end(), s.v.begin(), s.v.end());
      tau.insert(tau.end(), s.tau.begin(), s.tau.end());
      lambda0.insert(lambda0.end(), s.lambda0.begin(), s.lambda0.end());
    }
    for (bool warm : {false, true}) {
      g::Settings s;
      s.lambda0 = warm ? lambda0.data() : nullptr;
      const S canary = S(-12345.5);
      std::vector<S> qdd(std::size_t(g::nv * (n + 1)), canary), lambda(std::size_t(g::nc * (n + 1) + 1), canary);
      many(n, q.data(), v.data(), tau.data(), s, bw, qdd.data(), lambda.data());
      for (int k = 0; k < n; ++k) {
        const Answer a = scalarAnswer(scalar, st[std::size_t(k)], s, warm, w);
        // State k's outputs at k * nv and k * nc: expectLane with stride 1 reads [i + at].
        std::vector<S> qk(qdd.begin() + k * g::nv, qdd.begin() + (k + 1) * g::nv);
        std::vector<S> lk(lambda.begin() + k * g::nc, lambda.begin() + (k + 1) * g::nc);
        expectLane(a, qk, lk, 0, 1, what);
      }
      for (std::size_t i = std::size_t(g::nv * n); i < qdd.size(); ++i) EXPECT_EQ(qdd[i], canary) << what;
      for (std::size_t i = std::size_t(g::nc * n); i < lambda.size(); ++i) EXPECT_EQ(lambda[i], canary) << what;
    }
  }
  // n = 0 and n < 0: nothing read, nothing written.
  S untouched = S(3);
  g::Settings s;
  many(0, nullptr, nullptr, nullptr, s, bw, &untouched, &untouched);
  many(-4, nullptr, nullptr, nullptr, s, bw, &untouched, &untouched);
  EXPECT_EQ(untouched, S(3));
}

TEST(Batch, ConstrainedAbaLanesAreTheScalarSolver) {
  checkBatch(g::constrained_aba, g::constrained_aba_batch, "constrained_aba_batch");
}
TEST(Batch, ProxPvLanesAreTheScalarSolver) { checkBatch(g::prox_pv, g::prox_pv_batch, "prox_pv_batch"); }
TEST(Batch, ConstrainedAbaManyIsTheScalarSolverPerState) {
  checkMany(g::constrained_aba, g::constrained_aba_many, "constrained_aba_many");
}
TEST(Batch, ProxPvManyIsTheScalarSolverPerState) { checkMany(g::prox_pv, g::prox_pv_many, "prox_pv_many"); }

// The NaN state poisons its own lane only (the lanes share no value): the
// test above would pass with NaN everywhere if the scalar answer were NaN for
// every state, so the finite lanes are checked to be finite here.
TEST(Batch, ANaNStateStaysInItsLane) {
  static g::BatchWorkspace bw;
  const std::vector<State> st = states(6, 3u);  // state 5 holds a NaN q
  std::vector<S> q, v, tau;
  for (int k : {0, 5}) {
    q.insert(q.end(), st[std::size_t(k)].q.begin(), st[std::size_t(k)].q.end());
    v.insert(v.end(), st[std::size_t(k)].v.begin(), st[std::size_t(k)].v.end());
    tau.insert(tau.end(), st[std::size_t(k)].tau.begin(), st[std::size_t(k)].tau.end());
  }
  g::Settings s;
  std::vector<S> qdd(std::size_t(2 * g::nv)), lambda(std::size_t(2 * g::nc + 1));
  g::prox_pv_many(2, q.data(), v.data(), tau.data(), s, bw, qdd.data(), lambda.data());
  bool poisoned = false;  // the NaN state's own answer
  for (int i = 0; i < g::nv; ++i) {
    EXPECT_TRUE(std::isfinite(qdd[std::size_t(i)])) << "qdd[" << i << "] of the finite state";
    poisoned = poisoned || std::isnan(qdd[std::size_t(g::nv + i)]);
  }
  EXPECT_TRUE(poisoned);
}

// ---- The library functions over lanes (FUNCTIONS of the test solver) ----
// Each NAME_batch lane and each NAME_many state against the scalar NAME on
// the same inputs, bit for bit (the bound of the file's head: the lane forms
// are the scalar functions' text over lanes, compiled without contraction).
// Inputs per state: q and v of states() (the hostile ones among them), its
// tau as qdd and its lambda0 as lambda.
using LibraryScalar = std::function<void(const S* q, const S* v, const S* qdd, const S* lambda, g::Workspace& w, S* out)>;
using LibraryBatch =
    std::function<void(const S* q, const S* v, const S* qdd, const S* lambda, g::BatchWorkspace& w, S* out)>;
using LibraryMany =
    std::function<void(int n, const S* q, const S* v, const S* qdd, const S* lambda, g::BatchWorkspace& w, S* out)>;

[[maybe_unused]] void checkLibrary(const char* what, int size, const LibraryScalar& scalar, const LibraryBatch& batch,
                                   const LibraryMany& many) {
  static g::Workspace w;
  static g::BatchWorkspace bw;
  std::vector<S> expected(std::size_t(size) + 1);
  // W states lane-interleaved through NAME_batch.
  for (unsigned seed : {1u, 2u, 3u}) {
    const std::vector<State> st = states(W, seed);
    std::vector<S> q(std::size_t(g::nq * W)), v(std::size_t(g::nv * W)), qdd(std::size_t(g::nv * W)),
        lambda(std::size_t(g::nc * W + 1));
    for (int l = 0; l < W; ++l) {
      const State& x = st[std::size_t(l)];
      for (int i = 0; i < g::nq; ++i) q[std::size_t(i * W + l)] = x.q[std::size_t(i)];
      for (int i = 0; i < g::nv; ++i) v[std::size_t(i * W + l)] = x.v[std::size_t(i)];
      for (int i = 0; i < g::nv; ++i) qdd[std::size_t(i * W + l)] = x.tau[std::size_t(i)];
      for (int r = 0; r < g::nc; ++r) lambda[std::size_t(r * W + l)] = x.lambda0[std::size_t(r)];
    }
    std::vector<S> out(std::size_t(size * W) + 1);
    batch(q.data(), v.data(), qdd.data(), lambda.data(), bw, out.data());
    for (int l = 0; l < W; ++l) {
      const State& x = st[std::size_t(l)];
      scalar(x.q.data(), x.v.data(), x.tau.data(), x.lambda0.data(), w, expected.data());
      for (int i = 0; i < size; ++i)
        EXPECT_TRUE(sameBits(out[std::size_t(i * W + l)], expected[std::size_t(i)]))
            << what << "_batch [" << i << "] of lane " << l << " (seed " << seed << "): " << out[std::size_t(i * W + l)]
            << " vs " << expected[std::size_t(i)];
    }
  }
  // n states in the plain layout through NAME_many: n not a multiple of W
  // among them, nothing written past state n - 1.
  for (int n : {1, W - 1, W, 2 * W + 3}) {
    if (n < 1) continue;
    const std::vector<State> st = states(n, 11u + unsigned(n));
    std::vector<S> q, v, qdd, lambda;
    for (const State& x : st) {
      q.insert(q.end(), x.q.begin(), x.q.end());
      v.insert(v.end(), x.v.begin(), x.v.end());
      qdd.insert(qdd.end(), x.tau.begin(), x.tau.end());
      lambda.insert(lambda.end(), x.lambda0.begin(), x.lambda0.end());
    }
    lambda.push_back(S(0));  // (nc = 0: a valid pointer)
    const S canary = S(-12345.5);
    std::vector<S> out(std::size_t(size * (n + 1)) + 1, canary);
    many(n, q.data(), v.data(), qdd.data(), lambda.data(), bw, out.data());
    for (int k = 0; k < n; ++k) {
      const State& x = st[std::size_t(k)];
      scalar(x.q.data(), x.v.data(), x.tau.data(), x.lambda0.data(), w, expected.data());
      for (int i = 0; i < size; ++i)
        EXPECT_TRUE(sameBits(out[std::size_t(k * size + i)], expected[std::size_t(i)]))
            << what << "_many [" << i << "] of state " << k << " of " << n;
    }
    for (std::size_t i = std::size_t(size * n); i < out.size(); ++i) EXPECT_EQ(out[i], canary) << what << "_many, n " << n;
  }
  // n = 0 and n < 0: nothing read, nothing written.
  S untouched = S(3);
  many(0, nullptr, nullptr, nullptr, nullptr, bw, &untouched);
  many(-2, nullptr, nullptr, nullptr, nullptr, bw, &untouched);
  EXPECT_EQ(untouched, S(3)) << what << "_many with n <= 0";
}

// A schedule that is not the default: every other constraint off (shared by the lanes).
[[maybe_unused]] const bool* someInactive() {
  static bool schedule[g::ncons > 0 ? g::ncons : 1];
  for (int k = 0; k < g::ncons; ++k) schedule[k] = k % 2 == 1;
  return schedule;
}

// The three forms of NAME called as (q, v, qdd, lambda, w, out), with the
// remaining arguments ARGS... after out (nothing, or the schedule).
#define PROXGEN_LIBRARY_FORMS(NAME, CALL)                                                                        \
  [](const S* q, const S* v, const S* qdd, const S* lambda, g::Workspace& w, S* out) {                         \
    auto f = [&](auto&&... a) { g::NAME(a...); };                                                              \
    CALL;                                                                                                      \
  },                                                                                                           \
      [](const S* q, const S* v, const S* qdd, const S* lambda, g::BatchWorkspace& w, S* out) {                \
        auto f = [&](auto&&... a) { g::NAME##_batch(a...); };                                                  \
        CALL;                                                                                                  \
      },                                                                                                       \
      [](int n, const S* q, const S* v, const S* qdd, const S* lambda, g::BatchWorkspace& w, S* out) {         \
        auto f = [&](auto&&... a) { g::NAME##_many(n, a...); };                                                \
        CALL;                                                                                                  \
      }

#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS
TEST(BatchLibrary, InverseDynamics) {
  checkLibrary("inverse_dynamics", g::nv, PROXGEN_LIBRARY_FORMS(inverse_dynamics, f(q, v, qdd, lambda, w, out)));
  checkLibrary("inverse_dynamics (lambda null)", g::nv,
               PROXGEN_LIBRARY_FORMS(inverse_dynamics, (static_cast<void>(lambda), f(q, v, qdd, nullptr, w, out))));
  checkLibrary("inverse_dynamics (schedule)", g::nv,
               PROXGEN_LIBRARY_FORMS(inverse_dynamics, f(q, v, qdd, lambda, w, out, someInactive())));
}
#endif
#if PROXGEN_SOLVER_HAS_NONLINEAR_EFFECTS
TEST(BatchLibrary, NonlinearEffects) {
  checkLibrary("nonlinear_effects", g::nv,
               PROXGEN_LIBRARY_FORMS(nonlinear_effects, (static_cast<void>(qdd), static_cast<void>(lambda), f(q, v, w, out))));
}
#endif
#if PROXGEN_SOLVER_HAS_MASS_MATRIX
TEST(BatchLibrary, MassMatrix) {
  checkLibrary("mass_matrix", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(mass_matrix, (static_cast<void>(v), static_cast<void>(qdd),
                                                   static_cast<void>(lambda), f(q, w, out))));
}
#endif
#if PROXGEN_SOLVER_HAS_MASS_MATRIX_INVERSE
TEST(BatchLibrary, MassMatrixInverse) {
  checkLibrary("mass_matrix_inverse", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(mass_matrix_inverse, (static_cast<void>(v), static_cast<void>(qdd),
                                                           static_cast<void>(lambda), f(q, w, out))));
}
#endif
#if PROXGEN_SOLVER_HAS_CONSTRAINT_PLACEMENTS
TEST(BatchLibrary, ConstraintPlacements) {
  checkLibrary("constraint_placements", 12 * g::ncons,
               PROXGEN_LIBRARY_FORMS(constraint_placements, (static_cast<void>(v), static_cast<void>(qdd),
                                                             static_cast<void>(lambda), f(q, w, out))));
}
#endif
#if PROXGEN_SOLVER_HAS_CONSTRAINT_JACOBIAN
TEST(BatchLibrary, ConstraintJacobian) {
  checkLibrary("constraint_jacobian", g::nc * g::nv,
               PROXGEN_LIBRARY_FORMS(constraint_jacobian, (static_cast<void>(v), static_cast<void>(qdd),
                                                           static_cast<void>(lambda), f(q, w, out))));
  checkLibrary("constraint_jacobian (schedule)", g::nc * g::nv,
               PROXGEN_LIBRARY_FORMS(constraint_jacobian, (static_cast<void>(v), static_cast<void>(qdd),
                                                           static_cast<void>(lambda), f(q, w, out, someInactive()))));
}
#endif
#if PROXGEN_SOLVER_HAS_CONSTRAINT_DRIFT
TEST(BatchLibrary, ConstraintDrift) {
  checkLibrary("constraint_drift", g::nc,
               PROXGEN_LIBRARY_FORMS(constraint_drift, (static_cast<void>(qdd), static_cast<void>(lambda),
                                                        f(q, v, w, out))));
  checkLibrary("constraint_drift (schedule)", g::nc,
               PROXGEN_LIBRARY_FORMS(constraint_drift, (static_cast<void>(qdd), static_cast<void>(lambda),
                                                        f(q, v, w, out, someInactive()))));
}
#endif
#if PROXGEN_SOLVER_HAS_DELASSUS
TEST(BatchLibrary, Delassus) {
  checkLibrary("delassus", g::nc * g::nc,
               PROXGEN_LIBRARY_FORMS(delassus, (static_cast<void>(v), static_cast<void>(qdd),
                                                static_cast<void>(lambda), f(q, w, out))));
  checkLibrary("delassus (schedule)", g::nc * g::nc,
               PROXGEN_LIBRARY_FORMS(delassus, (static_cast<void>(v), static_cast<void>(qdd),
                                                static_cast<void>(lambda), f(q, w, out, someInactive()))));
}
#endif
#if PROXGEN_SOLVER_HAS_DELASSUS_INVERSE
// The Settings are shared by the lanes: the layout's mu and schedule, and mu =
// 100 with every other constraint off.
g::Settings otherSettings() {
  g::Settings s;
  s.mu = S(100);
  for (int k = 0; k < g::ncons; ++k) s.active[k] = someInactive()[k];
  return s;
}
TEST(BatchLibrary, DelassusInverse) {
  checkLibrary("delassus_inverse", g::nc * g::nc,
               PROXGEN_LIBRARY_FORMS(delassus_inverse, (static_cast<void>(v), static_cast<void>(qdd),
                                                        static_cast<void>(lambda), f(q, g::Settings{}, w, out))));
  checkLibrary("delassus_inverse (mu 100, schedule)", g::nc * g::nc,
               PROXGEN_LIBRARY_FORMS(delassus_inverse, (static_cast<void>(v), static_cast<void>(qdd),
                                                        static_cast<void>(lambda), f(q, otherSettings(), w, out))));
}
#endif
#if PROXGEN_SOLVER_HAS_CONSTRAINT_WRENCHES
TEST(BatchLibrary, ConstraintWrenches) {
  checkLibrary("constraint_wrenches", 6 * g::ncons,
               PROXGEN_LIBRARY_FORMS(constraint_wrenches, (static_cast<void>(v), static_cast<void>(qdd),
                                                           f(q, lambda, w, out))));
}
#endif

// The derivative functions write several outputs: each is checked in turn
// through `out`, the others go to scratch(k), each large enough for the
// _many calls' 2 W + 3 states of an nv x nv matrix.
[[maybe_unused]] S* scratch(int k) {
  static std::vector<S> buffers[3];
  std::vector<S>& b = buffers[k];
  if (b.empty()) b.resize(std::size_t(g::nv * g::nv * (2 * W + 4)) + 1);
  return b.data();
}

#if PROXGEN_SOLVER_HAS_INVERSE_DYNAMICS_DERIVATIVES
TEST(BatchLibrary, InverseDynamicsDerivatives) {
  checkLibrary("inverse_dynamics_derivatives dtau_dq", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(inverse_dynamics_derivatives, f(q, v, qdd, lambda, w, out, scratch(0))));
  checkLibrary("inverse_dynamics_derivatives dtau_dv", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(inverse_dynamics_derivatives, f(q, v, qdd, lambda, w, scratch(0), out)));
  checkLibrary("inverse_dynamics_derivatives (lambda null)", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(inverse_dynamics_derivatives,
                                     (static_cast<void>(lambda), f(q, v, qdd, nullptr, w, out, scratch(0)))));
}
#endif
#if PROXGEN_SOLVER_HAS_FORWARD_DYNAMICS_DERIVATIVES
// qdd's slot (the third input) carries tau here.
TEST(BatchLibrary, ForwardDynamicsDerivatives) {
  checkLibrary("forward_dynamics_derivatives qdd", g::nv,
               PROXGEN_LIBRARY_FORMS(forward_dynamics_derivatives,
                                     (static_cast<void>(lambda), f(q, v, qdd, w, out, scratch(0), scratch(1), scratch(2)))));
  checkLibrary("forward_dynamics_derivatives dqdd_dq", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(forward_dynamics_derivatives,
                                     (static_cast<void>(lambda), f(q, v, qdd, w, scratch(0), out, scratch(1), scratch(2)))));
  checkLibrary("forward_dynamics_derivatives dqdd_dv", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(forward_dynamics_derivatives,
                                     (static_cast<void>(lambda), f(q, v, qdd, w, scratch(0), scratch(1), out, scratch(2)))));
  checkLibrary("forward_dynamics_derivatives dqdd_dtau", g::nv * g::nv,
               PROXGEN_LIBRARY_FORMS(forward_dynamics_derivatives,
                                     (static_cast<void>(lambda), f(q, v, qdd, w, scratch(0), scratch(1), scratch(2), out))));
}
#endif

}  // namespace

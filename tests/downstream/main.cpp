// Links the solver generated at build time (arm_built) and the checked-in one
// (arm, from generated/arm): the same generator on the same inputs must give the
// same numbers to the last bit, and the Settings defaults must be the layout's.
// arm_built is generated with BATCH 4: its batched solvers (arm_built_batch.hpp)
// must give, state by state, the bits of arm_built's scalar solvers.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "arm.hpp"
#include "arm_built_batch.hpp"

// n = 2W + 3 states (two full batches and a remainder of 3, padded by the
// solver) through constrained_aba_many and prox_pv_many (warm-started, one
// lambda0 per state), each state against the scalar solver of the same files.
// The bound is zero, bit for bit: each lane runs the scalar solver's
// statements in the same order with the scalar IEEE operations, and both
// solvers are compiled with -ffp-contract=off (CMakeLists.txt), so no fused
// multiply-add can round one differently (docs/batch.md, "Lane by lane").
// A sentinel after state n - 1 must survive (nothing is written past n).
static int checkBatch(const arm_built::Settings& defaults) {
  static_assert(arm_built::batch_width == 4, "BATCH 4 did not reach the generator");
  constexpr int W = arm_built::batch_width, n = 2 * W + 3, nq = arm_built::nq, nv = arm_built::nv,
                nc = arm_built::nc;
  static double q[n * nq], v[n * nv], tau[n * nv], lam0[n * nc], qdd[n * nv + 1], lam[n * nc + 1];
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < nq; ++i) q[k * nq + i] = std::sin(1.0 + 7 * k + i) * 3;  // distinct states
    for (int i = 0; i < nv; ++i) {
      v[k * nv + i] = std::cos(2.0 + 5 * k + i);
      tau[k * nv + i] = 4 * std::sin(3.0 + 11 * k + i);
    }
    for (int i = 0; i < nc; ++i) lam0[k * nc + i] = std::cos(0.5 + 3 * k + i);
  }
  static arm_built::BatchWorkspace bw;
  static arm_built::Workspace w;
  const double sentinel = -12345.0;
  int bad = 0;
  for (int pass = 0; pass < 2; ++pass) {
    arm_built::Settings s = defaults;
    qdd[n * nv] = lam[n * nc] = sentinel;
    if (pass == 0) {
      arm_built::constrained_aba_many(n, q, v, tau, s, bw, qdd, lam);
    } else {
      s.lambda0 = lam0;
      arm_built::prox_pv_many(n, q, v, tau, s, bw, qdd, lam);
    }
    bad |= qdd[n * nv] != sentinel || lam[n * nc] != sentinel;
    for (int k = 0; k < n; ++k) {
      double qdd1[nv], lam1[nc];
      arm_built::Settings s1 = defaults;
      if (pass == 0) {
        arm_built::constrained_aba(q + k * nq, v + k * nv, tau + k * nv, s1, w, qdd1, lam1);
      } else {
        s1.lambda0 = lam0 + k * nc;
        arm_built::prox_pv(q + k * nq, v + k * nv, tau + k * nv, s1, w, qdd1, lam1);
      }
      const bool same = std::memcmp(qdd1, qdd + k * nv, sizeof qdd1) == 0 &&
                        std::memcmp(lam1, lam + k * nc, sizeof lam1) == 0;
      for (double x : qdd1) bad |= !std::isfinite(x);
      if (!same) std::printf("downstream: %s state %d differs from the scalar solver\n",
                             pass == 0 ? "constrained_aba_many" : "prox_pv_many", k);
      bad |= !same;
    }
  }
  std::printf("downstream: batched (W = %d), %d states: %s\n", W, n,
              bad ? "MISMATCH" : "each identical to the scalar solver");
  return bad;
}

int main(int argc, char** argv) {
  static_assert(arm_built::nv == arm::nv && arm_built::nc == arm::nc, "sizes differ");
  double q[arm_built::nq], v[arm_built::nv], tau[arm_built::nv];
  for (int k = 0; k < arm_built::nq; ++k) q[k] = 0.3 + 0.1 * k;
  for (int k = 0; k < arm_built::nv; ++k) {
    v[k] = 0.2 - 0.05 * k;
    tau[k] = 0.5 * std::sin(k);
  }
  static arm_built::Workspace wb;
  static arm::Workspace wa;
  double qddB[arm_built::nv], lamB[arm_built::nc], qddA[arm::nv], lamA[arm::nc];
  const arm_built::Settings sb;
  arm::Settings sa;
  sa.mu = sb.mu;  // the test may have changed the layout's mu: compare like with like
  sa.iterations = sb.iterations;
  arm_built::constrained_aba(q, v, tau, sb, wb, qddB, lamB);
  arm::constrained_aba(q, v, tau, sa, wa, qddA, lamA);
  int bad = std::memcmp(qddA, qddB, sizeof qddA) != 0 || std::memcmp(lamA, lamB, sizeof lamA) != 0;
  arm_built::prox_pv(q, v, tau, sb, wb, qddB, lamB);
  arm::prox_pv(q, v, tau, sa, wa, qddA, lamA);
  bad |= std::memcmp(qddA, qddB, sizeof qddA) != 0 || std::memcmp(lamA, lamB, sizeof lamA) != 0;
  for (double x : qddB) bad |= !std::isfinite(x);
  std::printf("downstream: mu = %.17g, iterations = %d, qdd[0] = %.17g: %s\n", double(sb.mu), sb.iterations,
              qddB[0], bad ? "MISMATCH" : "identical to the checked-in solver");
  bad |= checkBatch(sb);
  if (argc > 1 && std::strtod(argv[1], nullptr) != double(sb.mu)) {
    std::printf("downstream: expected Settings::mu = %s from the layout\n", argv[1]);
    return 1;
  }
  return bad;
}

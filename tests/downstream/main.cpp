// Links the solver generated at build time (arm_built) and the checked-in one
// (arm, from generated/arm): the same generator on the same inputs must give the
// same numbers to the last bit, and the Settings defaults must be the layout's.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "arm.hpp"
#include "arm_built.hpp"

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
  if (argc > 1 && std::strtod(argv[1], nullptr) != double(sb.mu)) {
    std::printf("downstream: expected Settings::mu = %s from the layout\n", argv[1]);
    return 1;
  }
  return bad;
}

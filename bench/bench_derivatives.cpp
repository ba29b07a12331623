// Instructions per call of the generated constrained_dynamics_derivatives
// against central differences of the generated prox_pv (2 calls per input
// direction, 3 nv directions: q, v, tau; 6 nv calls), for callgrind:
//   bench_derivatives cdd|fd N   runs N of them (N = 0: the set-up alone),
// and (Ir(N) - Ir(0)) / N is one call (bench/RESULTS.md, "Derivatives").
// The differences perturb q by q + h e_k in its own coordinates (a free
// flyer's quaternion entries too): the integration on the manifold a real
// finite-difference user needs is not counted, which favours the differences.
// Built by hand against one generated solver (no CMake target: the command is
// in bench/RESULTS.md):
//   g++ -std=c++17 -O2 -fno-tree-slp-vectorize -Iruntime -I<solver dir>
//       -DSOLVER_HEADER='"<name>.hpp"' -DSOLVER_NAMESPACE=<name> bench/bench_derivatives.cpp <solver lib>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include SOLVER_HEADER

namespace s = SOLVER_NAMESPACE;

namespace {

s::Workspace w;  // static: the derivative members are large
s::Scalar dq[s::nv * s::nv], dv[s::nv * s::nv], dt[s::nv * s::nv];
s::Scalar lq[s::nc * s::nv + 1], lv[s::nc * s::nv + 1], lt[s::nc * s::nv + 1];

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || (std::strcmp(argv[1], "cdd") != 0 && std::strcmp(argv[1], "fd") != 0)) {
    std::fprintf(stderr, "usage: %s cdd|fd N\n", argv[0]);
    return 2;
  }
  const bool cdd = std::strcmp(argv[1], "cdd") == 0;
  const int n = std::atoi(argv[2]);
  // A fixed state: every coordinate non-zero (a quaternion need not be unit).
  s::Scalar q[s::nq], v[s::nv], tau[s::nv], qdd[s::nv], lambda[s::nc + 1];
  for (int k = 0; k < s::nq; ++k) q[k] = s::Scalar(0.3 + 0.1 * (k % 5));
  for (int k = 0; k < s::nv; ++k) v[k] = s::Scalar(0.2 - 0.05 * (k % 7)), tau[k] = s::Scalar(0.5 * ((k % 3) - 1));
  const s::Settings st;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    if (cdd) {
      s::constrained_dynamics_derivatives(q, v, tau, st, w, qdd, lambda, dq, dv, dt, lq, lv, lt);
      sum += double(dq[i % (s::nv * s::nv)]);
      continue;
    }
    const s::Scalar h = s::Scalar(1e-6);
    s::Scalar* inputs[3] = {q, v, tau};
    for (int x = 0; x < 3; ++x)
      for (int k = 0; k < s::nv; ++k) {
        s::Scalar* in = inputs[x];
        const int at = x == 0 ? k % s::nq : k;
        const s::Scalar keep = in[at];
        in[at] = keep + h;
        s::prox_pv(q, v, tau, st, w, qdd, lambda);
        const s::Scalar plus = qdd[0];
        in[at] = keep - h;
        s::prox_pv(q, v, tau, st, w, qdd, lambda);
        in[at] = keep;
        sum += double((plus - qdd[0]) / (2 * h));
      }
  }
  std::printf("%g\n", sum);
  return 0;
}

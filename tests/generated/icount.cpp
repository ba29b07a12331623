// Driver for measure.sh --instructions: N calls of one generated solver
// (0: constrained_aba, 1: prox_pv) on a fixed state, K and mu from the layout;
// callgrind(N = 1000) - callgrind(N = 0), over 1000, is the cost of one call.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include SOLVER_HEADER

namespace gen = SOLVER;

static gen::Workspace w;

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  const int calls = std::atoi(argv[1]), algorithm = std::atoi(argv[2]);
  static gen::Scalar q[gen::nq], v[gen::nv], tau[gen::nv], qdd[gen::nv], lambda[gen::nc > 0 ? gen::nc : 1];
  for (int k = 0; k < gen::nq; ++k) q[k] = gen::Scalar(0.1 * std::sin(k + 1.0));
  if (gen::nq != gen::nv) {  // a free flyer: a unit quaternion in q[3..6]
    q[3] = gen::Scalar(0.1);
    q[4] = gen::Scalar(0.2);
    q[5] = gen::Scalar(0.3);
    q[6] = gen::Scalar(std::sqrt(1 - 0.14));
  }
  for (int k = 0; k < gen::nv; ++k) {
    v[k] = gen::Scalar(0.2 * std::cos(k));
    tau[k] = gen::Scalar(0.3 * std::sin(2.0 * k));
  }
  const gen::Settings s;
  double sum = 0;
  for (int n = 0; n < calls; ++n) {
    if (algorithm == 0) gen::constrained_aba(q, v, tau, s, w, qdd, lambda);
    else gen::prox_pv(q, v, tau, s, w, qdd, lambda);
    sum += double(qdd[0]);
  }
  std::printf("%g\n", sum);  // keeps the calls
  return 0;
}

// proxgen::core in a user's project: the robot and layout the solver was
// generated from are loaded by the generic library, and the generated solver
// (arm_built) is held to the bounds `proxgen verify` uses (verify/compare.hpp:
// max(1e-12, 10 n u kappa) at each state, the argument in compare.cpp), at the
// layout's mu and K and at K = 0 and 10, on 20 random states. A direct call of
// the generic constrainedABA shows the API a user cross-checks with.
// Usage: cross_check <urdf> <layout>
#include <algorithm>
#include <cstdio>
#include <random>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/data.hpp"
#include "arm_built.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "verify/compare.hpp"

namespace {

void runGenerated(bool pv, const proxgen::State& s, double mu, int K, proxgen::VecX& qdd, proxgen::VecX& lambda) {
  static arm_built::Workspace w;
  arm_built::Settings settings;
  settings.mu = mu;
  settings.iterations = K;
  qdd.resize(arm_built::nv);
  lambda.resize(arm_built::nc);
  if (pv) arm_built::prox_pv(s.q.data(), s.v.data(), s.tau.data(), settings, w, qdd.data(), lambda.data());
  else arm_built::constrained_aba(s.q.data(), s.v.data(), s.tau.data(), settings, w, qdd.data(), lambda.data());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: cross_check <urdf> <layout>\n");
    return 2;
  }
  const proxgen::System sys = proxgen::loadSystem(argv[1], argv[2]);
  if (sys.model.nq != arm_built::nq || sys.model.nv != arm_built::nv || sys.nc != arm_built::nc) {
    std::printf("cross_check: the loaded system (nq %d, nv %d, nc %d) is not the generated one\n", sys.model.nq,
                sys.model.nv, sys.nc);
    return 1;
  }
  proxgen::Data d(sys), scratch(sys);
  std::mt19937 rng(20261201);
  int failures = 0, compared = 0;
  double worstRatio = 0;
  for (int n = 0; n < 20; ++n) {
    const proxgen::State s = proxgen::randomState(sys.model, rng);
    const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(sys, scratch, s, false);
    const proxgen::verify::Bounds bounds = proxgen::verify::boundsAt(cond, sys.mu);
    for (int K : {0, sys.iterations, 10}) {
      proxgen::verify::GeneratedAnswer gen;
      runGenerated(false, s, sys.mu, K, gen.cabaQdd, gen.cabaLambda);
      runGenerated(true, s, sys.mu, K, gen.pvQdd, gen.pvLambda);
      const proxgen::verify::Comparison c = proxgen::verify::compareWithGeneric(sys, d, cond, bounds, s, K, gen);
      for (const proxgen::verify::Compared& x : c.item) {
        ++compared;
        if (!x.finite || !(x.error <= x.bound)) {
          ++failures;
          std::printf("cross_check: %s at state %d, K %d: error %.3g above its bound %.3g\n", x.what, n, K, x.error, x.bound);
        }
        worstRatio = std::max(worstRatio, x.error / x.bound);
      }
    }
  }
  // The generic solver called directly, as a user would.
  const proxgen::State s = proxgen::randomState(sys.model, rng);
  proxgen::constrainedAba(sys, d, s.q, s.v, s.tau, sys.mu, sys.iterations);
  proxgen::VecX qdd, lambda;
  runGenerated(false, s, sys.mu, sys.iterations, qdd, lambda);
  std::printf("cross_check: %d comparisons with proxgen::core, %d above their bound, largest error/bound %.3g; "
              "qdd[0] generic %.17g, generated %.17g\n",
              compared, failures, worstRatio, d.qdd[0], qdd[0]);
  return failures == 0 ? 0 : 1;
}

// The checks of one generated solver against the generic solvers it was generated from:
// 100 random states, K = 0, 1, 2, 3 and converged (100), mu = 100 and 1e4;
// the generated constrainedABA against constrainedAba, proxPV against proxPv.
//
// Compiled once (the Eigen-heavy part); harness.cpp, built once per solver,
// wraps the solver in a SolverUnderTest and calls these.
//
// Tolerance: the bounds of generator/verify/compare.cpp (argued there), the
// same `proxgen verify` applies, so a user's check and these tests agree.
// Each test prints its largest error and error / bound per algorithm and mu;
// over all of tests/generated the largest error / bound was 0.40 when this was
// written (a margin of 2.5). The 1e-12 is the floor, met wherever the
// conditioning allows it: constrainedABA at mu = 1e4 is not (1e-10 to 6e-10 on
// Solo and Atlas, the same size as the generic cABA's own distance to the
// dense reference, docs/verification.md).
// An error in the generated arithmetic (a dropped term, a wrong sign) shows at
// every state, including the well-conditioned ones: the test also requires, in
// double, that at least half of the states at mu = 100 have bounds below 1e-3,
// so no such error can hide behind ill-conditioned states.
#include "harness_lib.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "algorithms/data.hpp"
#include "cases/cases.hpp"
#include "model/layout.hpp"
#include "support.hpp"
#include "verify/compare.hpp"

namespace proxgen::test {
namespace {

struct Worst {
  double error = 0, ratio = 0;  // largest relErr, largest relErr / tolerance
  void add(double err, double tol) {
    error = std::max(error, err);
    ratio = std::max(ratio, err / tol);
  }
};

}  // namespace

System loadSolverSystem(const char* caseName, const char* urdf, const char* layout) {
  if (caseName) {
    for (const Case& c : sharedCases())
      if (c.name == caseName) return loadCaseSystem(c);
    ADD_FAILURE() << "case " << caseName << " not in the shared cases.yaml";
    return {};
  }
  return loadSystem(urdf, layout);
}

void expectMatchesTheGenericSolvers(const SolverUnderTest& gen, const System& sys) {
  const bool kFloat = gen.isFloat;
  Data d(sys), dense(sys);
  std::mt19937 rng(20261125);
  const std::vector<int> Ks = {0, 1, 2, 3, 100};
  const std::vector<double> mus = {100.0, 1e4};
  Worst worst[2][4];  // per mu: constrainedABA qdd, lambda; proxPV qdd, lambda
  verify::GeneratedAnswer answer;
  // States whose bounds at mu = 100 are tight enough that a wrong term (a
  // dropped or mis-signed contribution of 0.1 % of the answer or more) could not
  // pass: 1e-3. Checked in double only: a float solver is the same emitted code
  // with float literals, and float's u kappa (kappa(M) reaches 1e7 on Talos)
  // leaves its bounds above that at most states.
  const double kInformative = 1e-3;
  int informative = 0;
  // PROXGEN_HARNESS_STATES (default 100) lowers the count where each state is
  // costly and the point is another one: the sanitizer build (-O0, ASan) runs 5,
  // which reach every line of the solver as 100 do.
  const char* statesEnv = std::getenv("PROXGEN_HARNESS_STATES");
  const int states = statesEnv ? std::max(1, std::atoi(statesEnv)) : 100;
  for (int n = 0; n < states; ++n) {
    // The state as the generated solver sees it (inputs rounded to its Scalar),
    // so the generic solver answers the same question.
    const State s = verify::roundedToScalar(test::randomState(sys.model, rng), kFloat);
    const verify::Conditioning cond = verify::conditioningAt(sys, dense, s, kFloat);
    for (std::size_t m = 0; m < mus.size(); ++m) {
      const verify::Bounds bounds = verify::boundsAt(cond, mus[m]);
      if (m == 0) informative += bounds.primal <= kInformative && bounds.dual <= kInformative;
      for (int K : Ks) {
        const std::string where = "state " + std::to_string(n) + ", mu " + std::to_string(mus[m]) + ", K " + std::to_string(K);
        gen.run(SolverUnderTest::kConstrainedAba, s.q, s.v, s.tau, mus[m], K, answer.cabaQdd, answer.cabaLambda);
        gen.run(SolverUnderTest::kProxPv, s.q, s.v, s.tau, mus[m], K, answer.pvQdd, answer.pvLambda);
        const verify::Comparison c = verify::compareWithGeneric(sys, d, cond, bounds, s, K, answer);
        for (int q = 0; q < 4; ++q) {
          const verify::Compared& x = c.item[q];
          EXPECT_TRUE(x.finite) << x.what << " not finite, " << where;
          EXPECT_LE(x.error, x.bound) << x.what << ", " << where;
          worst[m][q].add(x.error, x.bound);
        }
      }
    }
  }
  // An error in the generated arithmetic shows at every state: it must not be
  // able to hide behind ill-conditioned ones.
  if (!kFloat) {
    EXPECT_GE(2 * informative, states) << "too few states where the bounds could catch a wrong term";
  }
  std::printf("states with bounds <= %g at mu = 100: %d of %d\n", kInformative, informative, states);
  for (std::size_t m = 0; m < mus.size(); ++m) {
    std::printf("mu = %g: largest relErr (and / tolerance): constrainedABA qdd %.1e (%.2f) lambda %.1e (%.2f), "
                "proxPV qdd %.1e (%.2f) lambda %.1e (%.2f)\n",
                mus[m], worst[m][0].error, worst[m][0].ratio, worst[m][1].error, worst[m][1].ratio, worst[m][2].error,
                worst[m][2].ratio, worst[m][3].error, worst[m][3].ratio);
  }
}

}  // namespace proxgen::test

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
#include <map>
#include <string>
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

// The joint-space functions. Bounds: verify/compare.cpp (torqueBound and the
// table there). The identities, on the generated functions alone:
//   M Minv - I: |M| |dMinv| + |dM| |Minv|, c n u kappa(M) relative to 1;
//   nonlinear_effects - inverse_dynamics(qdd = 0, nullptr): two RNEAs of the same
//     terms, each within torqueBound at qdd = 0, lambda = 0 (twice that bound);
//   inverse_dynamics(prox_pv's qdd, lambda) - tau: proxPV's qdd comes from a
//     final ABA sweep on tau - J^T lambda, backward stable, so its residual
//     M qdd + h + J^T lambda - tau is c n u times the size of the terms whatever
//     the conditioning: torqueBound with |tau| among the terms, twice (the
//     residual and this RNEA's own error). (constrainedABA's lambda = mu (J qdd - k)
//     carries mu u |J|^2 |qdd| into the residual: not this identity's bound.)
void expectLibraryMatchesTheGeneric(const LibraryUnderTest& lib, const SolverUnderTest* solver, const System& sys) {
  const bool kFloat = lib.isFloat;
  const Model& m = sys.model;
  Data d(sys), dense(sys);
  std::mt19937 rng(20261201);
  std::normal_distribution<double> normal(0.0, 1.0);
  const char* statesEnv = std::getenv("PROXGEN_HARNESS_STATES");
  const int states = statesEnv ? std::max(1, std::atoi(statesEnv)) : 100;
  std::map<std::string, Worst> worst;
  const auto check = [&](const std::string& what, double err, double bound, bool finite, const std::string& where) {
    EXPECT_TRUE(finite) << what << " not finite, " << where;
    EXPECT_LE(err, bound) << what << ", " << where;
    worst[what].add(err, bound);
  };
  const auto rounded = [&](VecX x) {
    if (kFloat)
      for (int k = 0; k < x.size(); ++k) x[k] = double(float(x[k]));
    return x;
  };
  for (int n = 0; n < states; ++n) {
    const std::string where = "state " + std::to_string(n);
    const State s = verify::roundedToScalar(test::randomState(m, rng), kFloat);
    const verify::Conditioning cond = verify::conditioningAt(sys, dense, s, kFloat);
    verify::LibraryAnswer gen;
    gen.qdd = VecX(m.nv);
    gen.lambda = VecX(sys.nc);
    for (int k = 0; k < m.nv; ++k) gen.qdd[k] = normal(rng);
    for (int k = 0; k < sys.nc; ++k) gen.lambda[k] = 10.0 * normal(rng);
    gen.qdd = rounded(gen.qdd);
    gen.lambda = rounded(gen.lambda);
    if (lib.inverseDynamics) lib.inverseDynamics(s.q, s.v, gen.qdd, &gen.lambda, gen.tau);
    if (lib.nonlinearEffects) lib.nonlinearEffects(s.q, s.v, gen.h);
    if (lib.massMatrix) lib.massMatrix(s.q, gen.M);
    if (lib.massMatrixInverse) lib.massMatrixInverse(s.q, gen.Minv);
    for (const verify::Compared& c : verify::compareLibraryWithGeneric(sys, d, cond, s, gen))
      check(c.what, c.error, c.bound, c.finite, where);
    const VecX none = VecX::Zero(sys.nc);
    if (lib.massMatrix && lib.massMatrixInverse)
      check("M Minv = I", verify::relErr(MatX(gen.M * gen.Minv), MatX::Identity(m.nv, m.nv)),
            std::max(cond.floor, cond.safety * cond.eps * cond.kappaM), true, where);
    if (lib.inverseDynamics && lib.nonlinearEffects) {
      VecX tau0;
      lib.inverseDynamics(s.q, s.v, d.zeroV, nullptr, tau0);
      check("nonlinear_effects = inverse_dynamics(0, nullptr)", verify::relErr(gen.h, tau0),
            2 * verify::torqueBound(sys, d, cond, s, d.zeroV, none, VecX::Zero(m.nv)), true, where);
    }
    if (lib.inverseDynamics && solver) {
      VecX qdd, lambda, tau;
      solver->run(SolverUnderTest::kProxPv, s.q, s.v, s.tau, sys.mu, 100, qdd, lambda);
      lib.inverseDynamics(s.q, s.v, qdd, &lambda, tau);
      check("inverse_dynamics(prox_pv's qdd, lambda) = tau", verify::relErr(tau, s.tau),
            2 * verify::torqueBound(sys, d, cond, s, qdd, lambda, s.tau), tau.allFinite(), where);
    }
  }
  EXPECT_FALSE(worst.empty()) << "the solver holds none of the joint-space functions";
  for (const auto& [what, w] : worst) std::printf("%s: largest relErr %.1e (%.2f of the bound)\n", what.c_str(), w.error, w.ratio);
}

}  // namespace proxgen::test

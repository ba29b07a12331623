// The warm start of the generic constrainedAba and proxPv (docs/algorithms.md
// §4.3): K multiplier updates from lambda0 instead of 0. Checked against the
// dense proximal iteration of §3 started from lambda0, written out here
// (qdd_free = M^-1 (tau - h), y = J qdd_free + gamma - a*, G = J M^-1 J^T,
// (G + I/mu) lambda_{k+1} = y + lambda_k / mu, qdd = qdd_free - M^-1 J^T lambda_K),
// and by the identity "one update from the K-th iterate is iterate K + 1".
//
// Tolerances: the round-off bounds of numerics.hpp (as test_equivalence.cpp),
// plus multiplierRoundoff for the size of lambda0; the identity compares two
// orders of the same backward-stable steps, each within the bound of the exact
// iterate: twice the bound.
#include "algorithms/constrained_aba.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/prox_pv.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::Bounds;

void denseFrom(const DenseProblem& p, double mu, int K, const VecX& lambda0, VecX& qdd, VecX& lambda) {
  const Eigen::LLT<MatX> M(p.M);
  const VecX qfree = M.solve(p.tau - p.h);
  const MatX MinvJt = M.solve(p.J.transpose());
  MatX A = p.J * MinvJt;
  A.diagonal().array() += 1.0 / mu;
  const Eigen::LLT<MatX> F(A);
  const VecX y = p.J * qfree + p.gamma - p.aStar;
  lambda = lambda0;
  for (int k = 0; k < K; ++k) lambda = F.solve(y + lambda / mu);
  qdd = qfree - MinvJt * lambda;
}

TEST(WarmStart, BothAlgorithmsIterateFromLambda0) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys);
    std::mt19937 rng(18);
    for (int st = 0; st < 2; ++st) {
      const test::RandomState s = test::randomState(sys.model, rng);
      const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
      for (double mu : {100.0, 1e4}) {
        const Bounds tol = test::roundoffBounds(p, mu);
        const std::string where = c.name + " state " + std::to_string(st) + " mu " + std::to_string(int(mu));
        // The previous step's multipliers: converged at the state with tau 10 % larger.
        VecX lambda0, unused;
        {
          DenseProblem prev = p;
          prev.tau *= 1.1;
          denseFrom(prev, mu, 200, VecX::Zero(sys.nc), unused, lambda0);
        }
        const double extra = test::multiplierRoundoff(p, lambda0);
        for (int K : {0, 1, 2, 3}) {
          VecX qRef, lRef;
          denseFrom(p, mu, K, lambda0, qRef, lRef);
          constrainedAbaFrom(sys, d, s.q, s.v, s.tau, mu, K, &lambda0);
          EXPECT_LE(test::relErr(d.qdd, qRef), tol.primal + extra) << where << " cABA K=" << K << " qdd";
          EXPECT_LE(test::relErr(d.lambda, lRef), tol.primal + extra) << where << " cABA K=" << K << " lambda";
          if (K == 0) {
            EXPECT_EQ(d.lambda, lambda0) << where << " cABA K=0 returns lambda0";
          }
          proxPvFrom(sys, d, s.q, s.v, s.tau, mu, K, &lambda0);
          EXPECT_LE(test::relErr(d.qdd, qRef), tol.dual + extra) << where << " proxPV K=" << K << " qdd";
          EXPECT_LE(test::relErr(d.lambda, lRef), tol.dual + extra) << where << " proxPV K=" << K << " lambda";
          if (K == 0) {
            EXPECT_EQ(d.lambda, lambda0) << where << " proxPV K=0 returns lambda0";
          }
        }
        // lambda0 is not a fixed point at this state: the test above can see a
        // warm start that is ignored (K = 1 from lambda0 vs from 0), at mu = 100
        // where the primal bound is tight (as test_equivalence.cpp's check of
        // the iteration count).
        if (mu == 100.0) {
          VecX q0, l0, q1, l1;
          denseFrom(p, mu, 1, VecX::Zero(sys.nc), q0, l0);
          denseFrom(p, mu, 1, lambda0, q1, l1);
          EXPECT_GT(test::relErr(l1, l0), 100 * (tol.primal + extra)) << where;
        }
      }
    }
  }
}

TEST(WarmStart, OneUpdateFromTheKthIterateIsIterateKPlusOne) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys), e(sys);
    std::mt19937 rng(19);
    const test::RandomState s = test::randomState(sys.model, rng);
    const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
    for (double mu : {100.0, 1e4}) {
      const Bounds tol = test::roundoffBounds(p, mu);
      for (int K : {2, 100}) {  // at K = 100 the iterate has converged: a fixed point
        const std::string where = c.name + " mu " + std::to_string(int(mu)) + " K " + std::to_string(K);
        constrainedAba(sys, d, s.q, s.v, s.tau, mu, K);
        const VecX fromK = d.lambda;
        const double extra = test::multiplierRoundoff(p, fromK);
        constrainedAbaFrom(sys, d, s.q, s.v, s.tau, mu, 1, &fromK);
        constrainedAba(sys, e, s.q, s.v, s.tau, mu, K + 1);
        EXPECT_LE(test::relErr(d.qdd, e.qdd), 2 * (tol.primal + extra)) << where << " cABA qdd";
        EXPECT_LE(test::relErr(d.lambda, e.lambda), 2 * (tol.primal + extra)) << where << " cABA lambda";
        proxPv(sys, d, s.q, s.v, s.tau, mu, K);
        const VecX fromKPv = d.lambda;
        proxPvFrom(sys, d, s.q, s.v, s.tau, mu, 1, &fromKPv);
        proxPv(sys, e, s.q, s.v, s.tau, mu, K + 1);
        EXPECT_LE(test::relErr(d.qdd, e.qdd), 2 * (tol.dual + extra)) << where << " proxPV qdd";
        EXPECT_LE(test::relErr(d.lambda, e.lambda), 2 * (tol.dual + extra)) << where << " proxPV lambda";
      }
    }
  }
}

}  // namespace
}  // namespace proxgen

// The checks of one generated solver against the generic solvers it was generated from:
// 100 random states, K = 0, 1, 2, 3 and converged (100), mu = 100 and 1e4;
// the generated constrainedABA against constrainedAba, proxPV against proxPv.
//
// Compiled once (the Eigen-heavy part); harness.cpp, built once per solver,
// wraps the solver in a SolverUnderTest and calls these.
//
// Tolerance. The generated code runs the recursions of the generic code with
// the operations in another order (constants folded, sums regrouped, the
// double-angle form of the joint rotations, a Cholesky for the free flyer's
// 6 x 6 inertia where the generic code inverts it, the Delassus factor by limbs
// plus a rank-6 Woodbury update). Each is backward stable, so each has a forward
// error of about c n u kappa (u the unit round-off of its Scalar, n = nv + nc
// steps, c = 10 as in the generic equivalence tests, tests/numerics.hpp), kappa
// the condition number of what the algorithm solves at that state; so has their
// difference:
//   constrainedABA qdd:    kappa(M + mu J^T J), the matrix every solve eliminates
//                          (it grows with mu: at mu = 1e4 on gram-scale
//                          fingertips cABA's own round-off reaches 1e-9);
//   constrainedABA lambda: lambda = mu (K a - k) is mu times a difference of
//                          body accelerations (J qdd, and gravity in both a and k),
//                          whose error it multiplies by mu:
//                          kappa (1 + mu (|J| |qdd| + |g|) / |lambda|);
//   proxPV qdd and lambda: kappa(M) (G and y_free come out of the articulated
//                          recursion) + kappa(G + I/mu) (the proximal solve).
// relErr (max |gen - generic| / max(1, max |generic|)) of each must stay below
// max(floor, c n u kappa); the floor is 1e-12 in double and 64 u = 4e-6 in
// float. Float solvers take inputs rounded to float, so that the generic
// solver (in double) answers the same question, and the same argument holds
// with float's u: at ill-conditioned states (a UR5e near a singular pose has
// kappa(G + I/mu) ~ 1e7) the float bound says little, which is what float can
// promise there. Each test prints its largest error and error / bound per
// algorithm and mu; over all of tests/generated the largest error / bound was
// 0.40 when this was written (a margin of 2.5). The 1e-12 is the floor,
// met wherever the conditioning allows it: constrainedABA at mu = 1e4 is not
// (1e-10 to 6e-10 on Solo and Atlas, the same size as the generic cABA's own
// distance to the dense reference, docs/verification.md).
// An error in the generated arithmetic (a dropped term, a wrong sign) shows at
// every state, including the well-conditioned ones: the test also requires, in
// double, that at least half of the states at mu = 100 have bounds below 1e-3,
// so no such error can hide behind ill-conditioned states.
#include "harness_lib.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/prox_pv.hpp"
#include "model/cases.hpp"
#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen::test {
namespace {

double conditionSym(const MatX& A) {
  if (A.rows() == 0) return 1.0;
  const Eigen::SelfAdjointEigenSolver<MatX> eig(A, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
}

double maxAbs1(const VecX& x) { return std::max(1.0, x.size() ? x.cwiseAbs().maxCoeff() : 0.0); }

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
  const double kEps = kFloat ? 5.9604644775390625e-08 : 1.1102230246251565e-16;  // unit round-off
  const double kFloor = kFloat ? 64 * kEps : 1e-12;
  const double kSafety = 10.0 * (gen.nv + gen.nc);  // c n
  // The state as the generated solver sees it (inputs rounded to its Scalar), so
  // the generic solver answers the same question.
  const auto rounded = [&](RandomState s) {
    for (VecX* x : {&s.q, &s.v, &s.tau})
      for (int k = 0; k < x->size(); ++k) (*x)[k] = kFloat ? double(float((*x)[k])) : (*x)[k];
    return s;
  };

  Data d(sys), dense(sys);
  std::mt19937 rng(20261125);
  const std::vector<int> Ks = {0, 1, 2, 3, 100};
  const std::vector<double> mus = {100.0, 1e4};
  Worst cq[2], cl[2], pq[2], pl[2];  // per mu: constrainedABA qdd, lambda; proxPV qdd, lambda
  VecX qdd, lambda;
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
    const RandomState s = rounded(test::randomState(sys.model, rng));
    crba(sys, dense, s.q);
    constraintJacobian(sys, dense, s.q, s.v);
    const MatX& M = dense.M;
    const MatX& J = dense.J;
    const double kM = conditionSym(M);
    for (std::size_t m = 0; m < mus.size(); ++m) {
      const double mu = mus[m];
      const double kC = conditionSym(M + mu * J.transpose() * J);
      MatX G = J * M.ldlt().solve(J.transpose());
      G.diagonal().array() += 1.0 / mu;
      const double dual = std::max(kFloor, kSafety * kEps * (kM + conditionSym(G)));
      const double primal = std::max(kFloor, kSafety * kEps * kC);
      if (m == 0) informative += primal <= kInformative && dual <= kInformative;
      for (int K : Ks) {
        const std::string where = "state " + std::to_string(n) + ", mu " + std::to_string(mu) + ", K " + std::to_string(K);
        constrainedAba(sys, d, s.q, s.v, s.tau, mu, K);
        gen.run(SolverUnderTest::kConstrainedAba, s.q, s.v, s.tau, mu, K, qdd, lambda);
        double err = relErr(qdd, d.qdd);
        EXPECT_LE(err, primal) << "constrained_aba qdd, " << where;
        cq[m].add(err, primal);
        const double accelerations = J.norm() * maxAbs1(d.qdd) + sys.model.gravity.norm();
        const double multiplier = std::max(primal, kSafety * kEps * kC * mu * accelerations / maxAbs1(d.lambda));
        err = relErr(lambda, d.lambda);
        EXPECT_LE(err, multiplier) << "constrained_aba lambda, " << where;
        cl[m].add(err, multiplier);

        proxPv(sys, d, s.q, s.v, s.tau, mu, K);
        gen.run(SolverUnderTest::kProxPv, s.q, s.v, s.tau, mu, K, qdd, lambda);
        err = relErr(qdd, d.qdd);
        EXPECT_LE(err, dual) << "prox_pv qdd, " << where;
        pq[m].add(err, dual);
        err = relErr(lambda, d.lambda);
        EXPECT_LE(err, dual) << "prox_pv lambda, " << where;
        pl[m].add(err, dual);
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
                mus[m], cq[m].error, cq[m].ratio, cl[m].error, cl[m].ratio, pq[m].error, pq[m].ratio, pl[m].error,
                pl[m].ratio);
  }
}

}  // namespace proxgen::test

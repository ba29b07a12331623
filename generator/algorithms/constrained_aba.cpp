#include "algorithms/constrained_aba.hpp"

#include "algorithms/aba.hpp"
#include "algorithms/constraints.hpp"

namespace proxgen {
namespace {

// lambda_c += mu (K_c a_i - k_c) for every constraint; keeps the increment in d.dlambda.
void updateMultipliers(const System& sys, Data& d, double mu) {
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    d.dlambda.segment(c.row, c.rows()) = mu * (d.terms[k].K * d.a[c.body] - d.terms[k].k);
  }
  d.lambda += d.dlambda;
}

}  // namespace

void constrainedAba(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu,
                    int iterations) {
  constrainedAbaFrom(sys, d, q, v, tau, mu, iterations, nullptr);
}

void constrainedAbaFrom(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu,
                        int iterations, const VecX* lambda0) {
  const Model& m = sys.model;
  const int N = m.numBodies();
  aba_steps::initialise(sys, d, q, v);
  computeConstraintTerms(sys, d);
  if (lambda0) d.lambda = *lambda0;
  else d.lambda.setZero();

  // The warm start's force on the constrained bodies (the force on the robot
  // is -K^T lambda): pA_i += K^T lambda0.
  if (lambda0)
    for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
      const Constraint& c = sys.constraints[k];
      if (c.body > 0) d.pA[c.body].noalias() += d.terms[k].K.transpose() * d.lambda.segment(c.row, c.rows());
    }
  // Penalty on the constrained bodies, before the backward pass:
  // IA_i += mu K^T K ; pA_i += -mu K^T k.
  if (iterations > 0) {
    for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
      const int i = sys.constraints[k].body;
      if (i == 0) continue;  // a constraint on the world moves nothing
      d.IA[i].noalias() += mu * d.terms[k].K.transpose() * d.terms[k].K;
      d.pA[i].noalias() -= mu * d.terms[k].K.transpose() * d.terms[k].k;
    }
  }
  for (int i = N - 1; i >= 1; --i) aba_steps::eliminate(sys, d, i, tau);
  aba_steps::setRootAcceleration(sys, d);
  for (int i = 1; i < N; ++i) aba_steps::accelerate(sys, d, i);
  if (iterations > 0) updateMultipliers(sys, d, mu);

  // Iterations 2..K: IA, U, D are unchanged; only the bias moves, linearly in
  // the latest multiplier increment, and only on the constraint support.
  for (int it = 2; it <= iterations; ++it) {
    for (int i : d.support) d.dp[i].setZero();
    for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
      const Constraint& c = sys.constraints[k];
      if (c.body > 0) d.dp[c.body].noalias() += d.terms[k].K.transpose() * d.dlambda.segment(c.row, c.rows());
    }
    for (auto it_i = d.support.rbegin(); it_i != d.support.rend(); ++it_i) {
      const int i = *it_i;
      const VecN du = -(d.S[i].transpose() * d.dp[i]);
      d.u[i] += du;
      const int p = m.bodies[i].parent;
      if (p > 0) d.dp[p] += d.liMi[i].actForce(d.dp[i] + d.U[i] * (d.Dinv[i] * du));
    }
    for (int i : d.support) aba_steps::accelerate(sys, d, i);
    updateMultipliers(sys, d, mu);
  }
  // The bodies off the support see their ancestors' final accelerations.
  if (iterations > 1)
    for (int i = 1; i < N; ++i)
      if (!d.onSupport[i]) aba_steps::accelerate(sys, d, i);
  d.iterationsDone = iterations;
  d.residual = constraintResidual(sys, d);
}

}  // namespace proxgen

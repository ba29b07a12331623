// The bounds a generated solver must meet against the generic solvers.
//
// The generated code runs the recursions of the generic code with the
// operations in another order (constants folded, sums regrouped, the
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
//                          recursion) + kappa(G + I/mu) (the proximal solve),
//                          per proximal step. The K steps carry each step's
//                          error on through lambda_k / mu, multiplied by at most
//                          rho = 1 / (1 + mu g_min) per step (g_min the smallest
//                          eigenvalue of G = J M^-1 J^T): the errors add up to
//                          (1 - rho^K) / (1 - rho) times one step's, about 1
//                          where G is well conditioned at this mu and K where a
//                          direction of G is not damped at all (redundant rows:
//                          lambda itself drifts along null(J^T) there,
//                          docs/derivatives.md). proximalAccumulation.
// relErr (max |gen - generic| / max(1, max |generic|)) of each must stay below
// max(floor, c n u kappa); the floor is 1e-12 in double and 64 u = 4e-6 in
// float. Float solvers take inputs rounded to float, so that the generic
// solver (in double) answers the same question, and the same argument holds
// with float's u: at ill-conditioned states (a UR5e near a singular pose has
// kappa(G + I/mu) ~ 1e7) the float bound says little, which is what float can
// promise there. Over all of tests/generated the largest error / bound was
// 0.40 when this was written (a margin of 2.5). An error in the generated
// arithmetic (a dropped term, a wrong sign) shows at every state, including
// the well-conditioned ones, where the bounds are tight (harness_lib.cpp
// requires enough of those).
#include "verify/compare.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/prox_pv.hpp"

namespace proxgen::verify {
namespace {

double conditionSym(const MatX& A) {
  if (A.rows() == 0) return 1.0;
  const Eigen::SelfAdjointEigenSolver<MatX> eig(A, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
}

double maxAbs1(const VecX& x) { return std::max(1.0, x.size() ? x.cwiseAbs().maxCoeff() : 0.0); }

bool allFinite(const VecX& x) { return x.size() == 0 || x.allFinite(); }

}  // namespace

double relErr(const VecX& a, const VecX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

State roundedToScalar(State s, bool isFloat) {
  if (!isFloat) return s;
  for (VecX* x : {&s.q, &s.v, &s.tau})
    for (int k = 0; k < x->size(); ++k) (*x)[k] = double(float((*x)[k]));
  return s;
}

Conditioning conditioningAt(const System& sys, Data& scratch, const State& s, bool isFloat) {
  Conditioning c;
  c.isFloat = isFloat;
  c.eps = isFloat ? 5.9604644775390625e-08 : 1.1102230246251565e-16;  // 2^-24, 2^-53
  c.floor = isFloat ? 64 * c.eps : 1e-12;
  c.safety = 10.0 * (sys.model.nv + sys.nc);
  crba(sys, scratch, s.q);
  constraintJacobian(sys, scratch, s.q, s.v);
  c.M = scratch.M;
  c.J = scratch.J;
  c.kappaM = conditionSym(c.M);
  return c;
}

Bounds boundsAt(const Conditioning& c, double mu) {
  Bounds b;
  b.mu = mu;
  b.kappaC = conditionSym(c.M + mu * c.J.transpose() * c.J);
  MatX G = c.J * c.M.ldlt().solve(c.J.transpose());
  if (G.rows() > 0) {
    const Eigen::SelfAdjointEigenSolver<MatX> eig(G, Eigen::EigenvaluesOnly);
    b.contraction = 1.0 / (1.0 + mu * std::max(0.0, eig.eigenvalues().minCoeff()));
  }
  G.diagonal().array() += 1.0 / mu;
  b.dual = std::max(c.floor, c.safety * c.eps * (c.kappaM + conditionSym(G)));
  b.primal = std::max(c.floor, c.safety * c.eps * b.kappaC);
  return b;
}

double proximalAccumulation(const Bounds& b, int K) {
  const double rho = b.contraction;
  if (K <= 1) return 1.0;
  if (rho >= 1.0 - 1e-12) return double(K);  // a direction G does not damp: every step's error stays
  return (1.0 - std::pow(rho, K)) / (1.0 - rho);
}

double cabaLambdaBound(const System& sys, const Conditioning& c, const Bounds& b, const VecX& genericQdd,
                       const VecX& genericLambda) {
  const double accelerations = c.J.norm() * maxAbs1(genericQdd) + sys.model.gravity.norm();
  return std::max(b.primal, c.safety * c.eps * b.kappaC * b.mu * accelerations / maxAbs1(genericLambda));
}

Comparison compareWithGeneric(const System& sys, Data& d, const Conditioning& c, const Bounds& b, const State& s,
                              int K, const GeneratedAnswer& gen) {
  Comparison out{};
  constrainedAba(sys, d, s.q, s.v, s.tau, b.mu, K);
  out.item[0] = {"constrained_aba qdd", relErr(gen.cabaQdd, d.qdd), b.primal,
                 allFinite(gen.cabaQdd) && allFinite(d.qdd)};
  out.item[1] = {"constrained_aba lambda", relErr(gen.cabaLambda, d.lambda), cabaLambdaBound(sys, c, b, d.qdd, d.lambda),
                 allFinite(gen.cabaLambda) && allFinite(d.lambda)};
  proxPv(sys, d, s.q, s.v, s.tau, b.mu, K);
  const double dual = b.dual * proximalAccumulation(b, K);
  out.item[2] = {"prox_pv qdd", relErr(gen.pvQdd, d.qdd), dual, allFinite(gen.pvQdd) && allFinite(d.qdd)};
  out.item[3] = {"prox_pv lambda", relErr(gen.pvLambda, d.lambda), dual, allFinite(gen.pvLambda) && allFinite(d.lambda)};
  return out;
}

// The dynamics library. inverse_dynamics, nonlinear_effects and mass_matrix
// are recursions without a solve (RNEA, CRBA): sums of products, whose forward
// error is c n u times the size of the terms summed, not of their result. For
// the torques that size is |M| |qdd| + |J|^T |lambda| + |h| + |g| (g = h at
// v = 0: the gravity that h's velocity terms may cancel); for M it is max |M|
// (every entry of a positive definite M is at most its largest diagonal entry,
// and the composite inertias summed are all positive semi-definite: no
// cancellation beyond that size). mass_matrix_inverse solves (the ABA on the
// unit torques): c n u kappa(M), relative to max(1, max |M^-1|).

double relErr(const MatX& a, const MatX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

double torqueBound(const System& sys, Data& d, const Conditioning& c, const State& s, const VecX& qdd, const VecX& lambda,
                   const VecX& tau) {
  VecX size = c.M.cwiseAbs() * qdd.cwiseAbs();
  if (sys.nc > 0) size += c.J.cwiseAbs().transpose() * lambda.cwiseAbs();
  const double h = nonLinearEffects(sys, d, s.q, s.v).cwiseAbs().maxCoeff();
  const double g = nonLinearEffects(sys, d, s.q, d.zeroV).cwiseAbs().maxCoeff();
  const double terms = (size.size() ? size.maxCoeff() : 0.0) + h + g + (tau.size() ? tau.cwiseAbs().maxCoeff() : 0.0);
  return std::max(c.floor, c.safety * c.eps * terms / maxAbs1(tau));
}

namespace {

bool allFinite(const MatX& x) { return x.size() == 0 || x.allFinite(); }

struct LibraryCheck {
  const char* what;
  bool (*held)(const LibraryAnswer&);
  Compared (*compare)(const System&, Data&, const Conditioning&, const State&, const LibraryAnswer&);
};

const LibraryCheck kLibrary[] = {
    {"inverse_dynamics", [](const LibraryAnswer& g) { return g.tau.size() > 0; },
     [](const System& sys, Data& d, const Conditioning& c, const State& s, const LibraryAnswer& g) {
       const VecX tau = inverseDynamics(sys, d, s.q, s.v, g.qdd, sys.nc > 0 ? &g.lambda : nullptr);
       return Compared{"inverse_dynamics tau", relErr(g.tau, tau), torqueBound(sys, d, c, s, g.qdd, g.lambda, VecX::Zero(tau.size())),
                       allFinite(g.tau) && allFinite(tau)};
     }},
    {"nonlinear_effects", [](const LibraryAnswer& g) { return g.h.size() > 0; },
     [](const System& sys, Data& d, const Conditioning& c, const State& s, const LibraryAnswer& g) {
       const VecX h = nonLinearEffects(sys, d, s.q, s.v);
       const VecX none = VecX::Zero(sys.nc);
       return Compared{"nonlinear_effects h", relErr(g.h, h), torqueBound(sys, d, c, s, d.zeroV, none, VecX::Zero(h.size())),
                       allFinite(g.h) && allFinite(h)};
     }},
    {"mass_matrix", [](const LibraryAnswer& g) { return g.M.size() > 0; },
     [](const System&, Data&, const Conditioning& c, const State&, const LibraryAnswer& g) {  // c.M: crba at s
       return Compared{"mass_matrix M", relErr(g.M, c.M), std::max(c.floor, c.safety * c.eps),
                       allFinite(g.M) && allFinite(c.M)};
     }},
    {"mass_matrix_inverse", [](const LibraryAnswer& g) { return g.Minv.size() > 0; },
     [](const System& sys, Data& d, const Conditioning& c, const State& s, const LibraryAnswer& g) {
       const MatX& Minv = massMatrixInverse(sys, d, s.q);
       return Compared{"mass_matrix_inverse", relErr(g.Minv, Minv), std::max(c.floor, c.safety * c.eps * c.kappaM),
                       allFinite(g.Minv) && allFinite(Minv)};
     }},
};

}  // namespace

std::vector<Compared> compareLibraryWithGeneric(const System& sys, Data& d, const Conditioning& c, const State& s,
                                                const LibraryAnswer& gen) {
  std::vector<Compared> out;
  for (const LibraryCheck& check : kLibrary)
    if (check.held(gen)) out.push_back(check.compare(sys, d, c, s, gen));
  return out;
}

// ---- The constraint functions. The generated code computes the same
// quantities as the generic one with the operations in another order (the
// same steps as argued above: c n u kappa, c n = safety):
//  - placements, J: products of the joint transforms along a path, each step
//    well conditioned (rotations): c n u relative to max(1, |reference|);
//  - gamma: sums of velocity products; the terms scale with |v|, so the bound
//    is c n u (1 + |v|_1) (as tests/algorithms/test_dynamics_library.cpp);
//  - G = J M^-1 J^T: a solve with M inside a recursion: c n u kappa(M);
//  - (G + I/mu)^-1 = mu I - mu^2 J M_mu^-1 J^T: the two terms cancel down to the
//    answer, so the absolute error is mu^2 times the error of J M_mu^-1 J^T
//    (c n u kappa(M_mu) / mu, as |J M_mu^-1 J^T| <= 1/mu): c n u kappa(M_mu) mu,
//    in the generic twin too (twice that for the difference), relative to
//    max(1, |reference|);
//  - wrenches W = -R lambda: each entry a sum of 3 products of rotation
//    entries (each within c n u, as the placements) with lambda: 3 c n u
//    |lambda|_inf, relative to max(1, |reference|).
std::vector<Compared> compareConstraintFunctions(const System& sys, Data& d, const Conditioning& c, const State& s,
                                                 const ConstraintAnswer& gen) {
  std::vector<Compared> out;
  const double base = std::max(c.floor, c.safety * c.eps);
  auto add = [&](const char* what, const VecX& g, const VecX& ref, double bound) {
    out.push_back({what, relErr(g, ref), bound, allFinite(g) && allFinite(ref)});
  };
  auto rowMajor = [](const MatX& A) {
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R = A;
    return VecX(Eigen::Map<const VecX>(R.data(), R.size()));
  };
  if (gen.X.size()) add("constraint_placements", gen.X, constraintPlacements(sys, d, s.q), base);
  if (gen.J.size()) add("constraint_jacobian", gen.J, rowMajor(constraintJacobianRows(sys, d, s.q)), base);
  if (gen.gamma.size())
    add("constraint_drift", gen.gamma, constraintDrift(sys, d, s.q, s.v), base * (1 + s.v.cwiseAbs().sum()));
  if (gen.G.size()) add("delassus", gen.G, rowMajor(delassus(sys, d, s.q)), std::max(c.floor, c.safety * c.eps * c.kappaM));
  if (gen.Ginv.size()) {
    const Bounds b = boundsAt(c, gen.mu);
    const VecX ref = rowMajor(delassusInverse(sys, d, s.q, gen.mu));
    add("delassus_inverse", gen.Ginv, ref, std::max(c.floor, 2 * c.safety * c.eps * b.kappaC * gen.mu / maxAbs1(ref)));
  }
  if (gen.W.size()) {
    const VecX ref = constraintWrenches(sys, d, s.q, gen.lambda);
    add("constraint_wrenches", gen.W, ref, std::max(c.floor, 3 * c.safety * c.eps * maxAbs1(gen.lambda) / maxAbs1(ref)));
  }
  return out;
}

// ---- The derivative functions. Both sides run the same sweep and the same
// solves with the sums in another order and other factors (ABA's M^-1 against
// CRBA + Cholesky, a dense factor of G + I/mu against Eigen's), so each entry
// differs by c n u times the size of the terms summed, not of the result (u,
// c n = safety as above; sizes |.| = max |entry|; relative to max(1, |generic|)):
//  - dtau (the sweep): c n u T, T the size of the sweep's terms (derivativeTerms:
//    the body force tangents, the forces, the inertia times the motion
//    tangents, times the lever 1 + |p| of a transform to the parent);
//  - forward dqdd (M^-1 times the sweep's result): c n u kappa(M) m nv (|dtau| + T),
//    m = max(1, |M^-1|); dqdd/dtau = M^-1: c n u kappa(M); qdd: c n u kappa m nv (|tau| + |h| + |g|);
//  - constrained: X0 = M^-1 R1 (R1 = [-dtau_dq, -dtau_dv, I]) is a solve with
//    M: eX0 = c n u (kappa |X0| + m nv T) (its own error, and the sweep's
//    through M^-1); C = J X0 - R2: eC = |J| nv eX0 + c n u (|J| nv |X0| + |R2| + R
//    + (|G| + 1/mu) nc |L|) (R: the rows' terms, motion tangents times 1 + |v|
//    and the gains; the last: G's product with L and the factor's solves at
//    every step). The K proximal steps on the tangents,
//    L_K = sum_{k<K} mu^-k (G + I/mu)^-(k+1) C, are one symmetric operator
//    S_K = V diag(s(g)) V^T over G's eigenvalues g, s(g) = (1 - (1 + mu g)^-K) / g
//    (K mu on null(G)): eL = |S_K| eC (|.| of an operator: its largest row sum);
//    X = X0 - M^-1 J^T L: eX = eX0 + |M^-1 J^T S_K| eC + c n u kappa |M^-1 J^T| nc |L|
//    (J^T annihilates what S_K amplifies along null(J^T), K mu: the
//    multipliers carry it, qdd does not);
//    qdd and lambda (prox_pv's solve, the same steps on y = J qfree + gamma - a*,
//    qfree = M^-1 (tau - h)): ey = c n u (kappa (|J| nv |qfree| + |da*| + R) + (|G| + 1/mu) nc |lambda|),
//    eLam = |S_K| ey, eQdd = c n u kappa (|qfree| + |M^-1 J^T| nc |lambda|) + |M^-1 J^T S_K| ey.
// A dropped term (the gravity tangent of the rows' true acceleration, Jr(e)^-1,
// a velocity product) moves entries by O(1) of the rows' size, far above these
// at well-conditioned states (tests/generated/harness_derivatives.cpp; tried by hand).
namespace {

double maxAbsM(const MatX& a) { return a.size() ? a.cwiseAbs().maxCoeff() : 0.0; }

double derivativeTerms(const System& sys, const Data& d, const DerivativeData& dd) {
  double T = 0.0;
  for (int i = 1; i < sys.model.numBodies(); ++i) {
    const std::size_t b = std::size_t(i);
    const double lever = 1.0 + d.liMi[b].p.norm();
    const double I = sys.model.bodies[b].inertia.matrix().cwiseAbs().maxCoeff();
    const double vi = d.v[b].cwiseAbs().maxCoeff();
    const double motion = std::max({maxAbsM(dd.da_dq[b]), maxAbsM(dd.da_dv[b]), dd.a[b].cwiseAbs().maxCoeff()}) +
                          2.0 * vi * std::max(maxAbsM(dd.dv_dq[b]), maxAbsM(dd.dv_dv[b]));
    T = std::max({T, lever * maxAbsM(dd.df_dq[b]), lever * maxAbsM(dd.df_dv[b]), lever * dd.f[b].cwiseAbs().maxCoeff(),
                  lever * 6.0 * I * motion});
  }
  return T;
}

// The K proximal steps on the tangents as one operator, L_K = S_K C:
// S_K = sum_{k<K} mu^-k (G + I/mu)^-(k+1) = V diag(s(g)) V^T over G's
// eigenvalues g, s(g) = (1 - (1 + mu g)^-K) / g (K mu on null(G)).
MatX proximalOperator(const MatX& G, double mu, int K) {
  if (G.rows() == 0) return G;
  const Eigen::SelfAdjointEigenSolver<MatX> eig(G);
  VecX s(G.rows());
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    const double g = std::max(0.0, eig.eigenvalues()[k]);
    s[k] = g * mu > 1e-12 ? (1.0 - std::pow(1.0 + mu * g, -K)) / g : K * mu;
  }
  return eig.eigenvectors() * s.asDiagonal() * eig.eigenvectors().transpose();
}

// max_r sum_c |A(r, c)|: the factor a perturbation of size e per entry of x grows by in A x.
double rowSum(const MatX& A) { return A.size() ? A.cwiseAbs().rowwise().sum().maxCoeff() : 0.0; }

}  // namespace

std::vector<Compared> compareDerivatives(const System& sys, Data& d, const Conditioning& c, const State& s,
                                         const DerivativeAnswer& gen) {
  std::vector<Compared> out;
  const int nv = sys.model.nv, nc = sys.nc;
  const double u = c.safety * c.eps;
  DerivativeData dd(sys);
  const auto add = [&](const char* what, const MatX& g, const MatX& ref, double absBound) {
    const bool finite = (g.size() == 0 || g.allFinite()) && (ref.size() == 0 || ref.allFinite());
    out.push_back({what, relErr(g, ref), std::max(c.floor, absBound / std::max(1.0, maxAbsM(ref))), finite});
  };
  const MatX Minv = c.M.llt().solve(MatX::Identity(nv, nv));
  const double m = std::max(1.0, maxAbsM(Minv));
  const VecX h = nonLinearEffects(sys, d, s.q, s.v);
  if (gen.dtau_dq.size()) {
    inverseDynamicsDerivatives(sys, d, dd, s.q, s.v, gen.qdd, nc > 0 ? &gen.lambda : nullptr);
    const double T = derivativeTerms(sys, d, dd);
    add("inverse_dynamics_derivatives dtau_dq", gen.dtau_dq, dd.dtau_dq, u * T);
    add("inverse_dynamics_derivatives dtau_dv", gen.dtau_dv, dd.dtau_dv, u * T);
  }
  if (gen.fDq.size()) {
    forwardDynamicsDerivatives(sys, d, dd, s.q, s.v, gen.tau);
    const double T = derivativeTerms(sys, d, dd);
    const VecX g = nonLinearEffects(sys, d, s.q, d.zeroV);
    const double k = u * c.kappaM * m * nv;
    const double rhs = maxAbsM(gen.tau) + maxAbsM(h) + maxAbsM(g);
    add("forward_dynamics_derivatives qdd", gen.fQdd, dd.qdd, k * rhs);
    add("forward_dynamics_derivatives dqdd_dq", gen.fDq, dd.dqdd_dq, k * (maxAbsM(dd.dtau_dq) + T));
    add("forward_dynamics_derivatives dqdd_dv", gen.fDv, dd.dqdd_dv, k * (maxAbsM(dd.dtau_dv) + T));
    add("forward_dynamics_derivatives dqdd_dtau", gen.fDtau, dd.dqdd_dtau, u * c.kappaM * m);
  }
  if (gen.cDq.size()) {
    constrainedDynamicsDerivatives(sys, d, dd, s.q, s.v, gen.tau, gen.mu, gen.K);
    const double T = derivativeTerms(sys, d, dd);
    double motion = 0.0;  // the rows' terms: motion tangents, times 1 + |v| in the velocity products
    for (int i = 1; i < sys.model.numBodies(); ++i) {
      const std::size_t b = std::size_t(i);
      const double vi = 1.0 + d.v[b].cwiseAbs().maxCoeff();
      motion = std::max({motion, vi * maxAbsM(dd.dv_dq[b]), vi * maxAbsM(dd.dv_dv[b]), maxAbsM(dd.da_dq[b]),
                         maxAbsM(dd.da_dv[b]), maxAbsM(dd.dg_dq[b])});
    }
    double gains = 1.0;
    for (const Constraint& con : sys.constraints) gains = std::max({gains, con.kp, con.kd});
    const MatX G = dd.J * Minv * dd.J.transpose();
    const MatX S = proximalOperator(G, gen.mu, gen.K);
    const MatX MinvJt = Minv * dd.J.transpose();
    const double A = rowSum(S), P = rowSum(MinvJt * S);  // |S_K|, |M^-1 J^T S_K|
    // X0 = M^-1 R1, R1 = [-dtau_dq, -dtau_dv, I]: its entries' size.
    const double X0 = std::max({maxAbsM(Minv * dd.dtau_dq), maxAbsM(Minv * dd.dtau_dv), maxAbsM(Minv)});
    const double R2 = std::max(maxAbsM(dd.dastar_dq - dd.dalpha_dq), maxAbsM(dd.dastar_dv - dd.dalpha_dv));
    const double J = maxAbsM(dd.J), R = gains * motion;
    const double Ls = std::max({maxAbsM(dd.dlambda_dq), maxAbsM(dd.dlambda_dv), maxAbsM(dd.dlambda_dtau)});
    const double eX0 = u * (c.kappaM * X0 + m * nv * T);
    const double eC = J * nv * eX0 + u * (J * nv * X0 + R2 + R + (maxAbsM(G) + 1.0 / gen.mu) * nc * Ls);
    const double eL = A * eC;
    const double eX = eX0 + P * eC + u * c.kappaM * maxAbsM(MinvJt) * nc * Ls;
    const VecX qfree = Minv * (gen.tau - h);
    const double y = J * nv * maxAbsM(qfree) + maxAbsM(dd.dastar_dq) + R;
    const double ey = u * (c.kappaM * y + (maxAbsM(G) + 1.0 / gen.mu) * nc * maxAbsM(dd.lambda));
    const double eLam = A * ey;
    const double eQdd = u * c.kappaM * (maxAbsM(qfree) + maxAbsM(MinvJt) * nc * maxAbsM(dd.lambda)) + P * ey;
    add("constrained_dynamics_derivatives qdd", gen.cQdd, dd.qdd, eQdd);
    add("constrained_dynamics_derivatives lambda", gen.cLambda, dd.lambda, eLam);
    add("constrained_dynamics_derivatives dqdd_dq", gen.cDq, dd.dqdd_dq, eX);
    add("constrained_dynamics_derivatives dqdd_dv", gen.cDv, dd.dqdd_dv, eX);
    add("constrained_dynamics_derivatives dqdd_dtau", gen.cDtau, dd.dqdd_dtau, eX);
    add("constrained_dynamics_derivatives dlambda_dq", gen.cLq, dd.dlambda_dq, eL);
    add("constrained_dynamics_derivatives dlambda_dv", gen.cLv, dd.dlambda_dv, eL);
    add("constrained_dynamics_derivatives dlambda_dtau", gen.cLtau, dd.dlambda_dtau, eL);
  }
  return out;
}

}  // namespace proxgen::verify

#include "emit/assemble.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <stdexcept>
#include <utility>

#include "emit/c_api.hpp"
#include "emit/identifiers.hpp"

namespace proxgen::emit {
namespace {

// The file skeletons, compiled in (an installed proxgen needs no source tree).
const char* const kBannerTemplate =
#include "../../templates/banner.tpl"
    ;
const char* const kHeaderTemplate =
#include "../../templates/solver.hpp.tpl"
    ;
const char* const kSourceTemplate =
#include "../../templates/solver.cpp.tpl"
    ;

std::string scalarName(ScalarType t) { return t == ScalarType::Float ? "float" : "double"; }

// The functions of the bodies off the constraint support; none when every
// body is on it (no empty functions).
std::string freeBodies(const SolverTexts& texts) {
  if (texts.eliminateFree.empty() && texts.accelerateFree.empty()) return "";
  return fmt::format(
      "// Articulated-body elimination of the bodies off the constraint support\n"
      "// (no constraint below them): the same in both algorithms.\n"
      "void eliminate_free_bodies(const Scalar* tau, Workspace& w) noexcept {{\n{}}}\n\n"
      "// Accelerations of the bodies off the support, once their ancestors are final.\n"
      "void accelerate_free_bodies(Workspace& w) noexcept {{\n{}}}\n\n",
      texts.eliminateFree, texts.accelerateFree);
}

// "a + b K" (b = 0: "a").
std::string affine(long once, long perK) {
  if (perK == 0) return fmt::format("{}", once);
  return fmt::format("{} + {} K", once, perK);
}

// One entry point's line of the banner's operation count (docs/emitter.md).
std::string opLine(const std::string& name, const OpCount& n, int K) {
  const Ops& a = n.once;
  const Ops& b = n.perK;
  return fmt::format(
      "//   {}: {} (= {} at K = {})\n"
      "//     add/sub {}, mul {}, div {}, neg {}, sqrt {}, sincos {}, log6 {}\n",
      name, affine(a.total(), b.total()), n.at(K).total(), K, affine(a.add, b.add), affine(a.mul, b.mul),
      affine(a.div, b.div), affine(a.neg, b.neg), affine(a.sqrt, b.sqrt), affine(a.sincos, b.sincos),
      affine(a.log6, b.log6));
}

// The entry points, in allFunctions() order: what the header declares (with
// its comment) and the source defines, for the functions the solver holds.
struct EntryPoint {
  Function f;
  const char* header;  // comment lines above the declaration ("" for prox_pv: constrained_aba's)
  const char* signature;
  const char* source;  // comment lines above the definition
};
const EntryPoint kEntryPoints[] = {
    {Function::ConstrainedAba,
     "// In: q[nq], v[nv], tau[nv] (none of them inside w). The quaternion of a free\n"
     "// flyer need not be unit: it is normalised as `proxgen eval` does (divided by\n"
     "// its largest magnitude, then by its norm), so the quaternion scaled by any\n"
     "// non-zero factor gives the same answer (bit for bit for a power of two or -1,\n"
     "// else to round-off). A zero quaternion (eval refuses it) or a non-finite one\n"
     "// gives NaN in every output.\n"
     "// Out: qdd[nv] and lambda[nc] (none of them inside w), lambda in layout order.\n"
     "// Sign: the constraint force on the robot is -J^T lambda, so\n"
     "// M qdd + h = tau - J^T lambda: a contact force f on the robot, in a library\n"
     "// where it enters as + J^T f, is -lambda (constraint_wrenches, a function\n"
     "// to select, gives each constraint's as a wrench on the robot in world axes).\n"
     "// K = s.iterations proximal multiplier updates\n"
     "//   lambda_{k+1} = lambda_k + mu (J qdd_{k+1} + gamma - a*)\n"
     "// from lambda_0 = s.lambda0 (or 0); both algorithms give the same iterates up to\n"
     "// round-off. From a lambda0 that already solves the constraints the update\n"
     "// adds nothing: lambda0 is a fixed point, at any K (docs/algorithms.md, 4.3).\n"
     "// Schedule: a constraint k with !s.active[k] exerts no force: its lambda rows are\n"
     "// exactly 0, its lambda0 rows are never read, its residual rows count as 0, and\n"
     "// qdd and the other rows are those of the solver generated without it (to\n"
     "// round-off), for any combination; no branch, no allocation (4.4).\n",
     "void constrained_aba(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,\n"
     "                     Scalar* qdd, Scalar* lambda) noexcept",
     "// constrainedABA: the penalty mu K^T K at the constrained bodies, one full\n"
     "// sweep, then iterations 2..K as reduced sweeps over the support.\n"},
    {Function::ProxPv, "",
     "void prox_pv(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,\n"
     "             Scalar* qdd, Scalar* lambda) noexcept",
     "// proxPV: one sweep carrying the constraint rows up the support, the Delassus\n"
     "// matrix G + I/mu factored once at the root, K proximal solves, one forward sweep.\n"},
    {Function::InverseDynamics,
     "\n// tau = M(q) qdd + h(q, v) + J(q)^T lambda (the constraint force on the robot is\n"
     "// -J^T lambda, as in the solvers): the torques that give the accelerations qdd\n"
     "// while the constraints push with multipliers lambda (rows in layout order, J's\n"
     "// rows in the constraint frames the solvers use); lambda may be nullptr (none).\n"
     "// active (ncons flags, as Settings::active; default all): the rows of an\n"
     "// inactive constraint are never read, as if its lambda were 0.\n",
     "void inverse_dynamics(const Scalar* q, const Scalar* v, const Scalar* qdd, const Scalar* lambda, Workspace& w,\n"
     "                      Scalar* tau, const bool* active) noexcept",
     "// Inverse dynamics (RNEA): kinematics, accelerations and forces root first,\n"
     "// with the constraint forces K^T lambda at the constrained bodies, then torques leaves first.\n"},
    {Function::NonlinearEffects,
     "\n// h(q, v) = inverse_dynamics(q, v, qdd = 0, nullptr): Coriolis, centrifugal and gravity torques.\n",
     "void nonlinear_effects(const Scalar* q, const Scalar* v, Workspace& w, Scalar* h) noexcept",
     "// Nonlinear effects: RNEA with qdd = 0 and no constraint forces.\n"},
    {Function::MassMatrix, "\n// M(q), the joint-space inertia: nv x nv, row-major, full (M[r * nv + c]).\n",
     "void mass_matrix(const Scalar* q, Workspace& w, Scalar* M) noexcept",
     "// The joint-space inertia by the composite-rigid-body algorithm.\n"},
    {Function::MassMatrixInverse,
     "\n// M(q)^-1: nv x nv, row-major, full, in O(n^2) without factoring M.\n",
     "void mass_matrix_inverse(const Scalar* q, Workspace& w, Scalar* Minv) noexcept",
     "// M^-1 by ABA on the nv unit torques at once (v = 0, no gravity).\n"},
    {Function::ConstraintPlacements,
     "\n// The constraint functions: rows in layout order, in the constraint frames the\n"
     "// solvers use (6d weld: [linear; angular] of the frame, in the frame; 3d point:\n"
     "// the linear rows); the constraint force on the robot is -J^T lambda.\n"
     "// The schedule (active: ncons flags as Settings::active, default all_active):\n"
     "// an inactive constraint's rows (and columns of G) are exact zeros; (G + I/mu)^-1\n"
     "// is that of the active rows alone, zeros elsewhere. The placements are geometry:\n"
     "// they take no schedule (docs/algorithms.md, 4.4).\n"
     "// Per constraint (layout order) 12 values: its frame's rotation in the world\n"
     "// (3 x 3, row-major), then the frame's origin in the world.\n",
     "void constraint_placements(const Scalar* q, Workspace& w, Scalar* X) noexcept",
     "// The constraint frames in the world: the support bodies' placements root first.\n"},
    {Function::ConstraintJacobian, "\n// J (nc x nv, row-major): the constraint frames' velocity rows are J v.\n",
     "void constraint_jacobian(const Scalar* q, Workspace& w, Scalar* J, const bool* active) noexcept",
     "// J: each row's direction carried up the tree as a force; each joint reads its column.\n"},
    {Function::ConstraintDrift,
     "\n// gamma (nc): J qdd + gamma is the constraint frames' acceleration the solvers\n"
     "// hold to a* (of a point, the classical acceleration of its origin).\n",
     "void constraint_drift(const Scalar* q, const Scalar* v, Workspace& w, Scalar* gamma, const bool* active) noexcept",
     "// gamma: the rows' acceleration at qdd = 0 without gravity, plus w x v for a point.\n"},
    {Function::Delassus,
     "\n// G = J M^-1 J^T (nc x nc, row-major), by a recursion over the constraint\n"
     "// support: neither M nor J is formed.\n",
     "void delassus(const Scalar* q, Workspace& w, Scalar* G, const bool* active) noexcept",
     "// G: the articulated inertias, the apparent inverse inertias Phi root first, and\n"
     "// every entry once where its two rows meet (O(n + m^2)).\n"},
    {Function::DelassusInverse,
     "\n// (G + I / s.mu)^-1 (nc x nc, row-major) = mu I - mu^2 J (M + mu J^T J)^-1 J^T by the\n"
     "// same recursion with the penalty mu J^T J, no nc x nc factorisation. The two\n"
     "// terms cancel: its absolute round-off is about eps kappa(M + mu J^T J) mu (in\n"
     "// float at large mu, factor delassus's G instead).\n",
     "void delassus_inverse(const Scalar* q, const Settings& s, Workspace& w, Scalar* Ginv) noexcept",
     "// (G + I/mu)^-1 by Woodbury on the penalised recursion.\n"},
    {Function::ConstraintWrenches,
     "\n// Per constraint (layout order) 6 values: the wrench of its multipliers ON THE\n"
     "// ROBOT in world axes, force then torque about the constraint frame's origin\n"
     "// (constraint_placements' position). With the solvers' sign (the constraint\n"
     "// force on the robot is -J^T lambda): -R [lambda_lin; lambda_ang] for a 6d\n"
     "// weld, [-R lambda; 0] for a 3d point (R: the frame's rotation in the world),\n"
     "// zeros for a constraint on the world. So the force the robot pushes the\n"
     "// ground with is minus W's; standing still, W's forces sum to -m g. lambda: nc\n"
     "// values (a solver's output), none of them inside w.\n",
     "void constraint_wrenches(const Scalar* q, const Scalar* lambda, Workspace& w, Scalar* W) noexcept",
     "// The wrenches: the support bodies' world rotations root first, -R_C lambda at each constraint.\n"},
    {Function::InverseDynamicsDerivatives,
     "\n// The derivatives of the dynamics (docs/derivatives.md). Every matrix is dense and\n"
     "// row-major: row = output component, column = input component (M[r * cols + c]).\n"
     "// Tangent convention of every d/dq: column k is the derivative along q (+) t e_k,\n"
     "// t -> 0, where q (+) dq is q + dq for revolute, continuous and prismatic joints,\n"
     "// and for a free flyer the placement M(q) Exp(dq), dq = [linear; angular] in the\n"
     "// base frame (the right perturbation of Pinocchio's integrate); likewise\n"
     "// M(q) Exp([dx dy 0 0 0 dyaw]) in the joint frame for a planar joint. So d/dq has\n"
     "// nv columns, like d/dv.\n"
     "// inverse_dynamics_derivatives: dtau_dq, dtau_dv (nv x nv each) of\n"
     "// tau = M(q) qdd + h(q, v) + J(q)^T lambda (as inverse_dynamics) at fixed qdd and\n"
     "// lambda; lambda may be nullptr (no constraint forces). Every constraint counts\n"
     "// as active. None of the arrays may be inside w.\n",
     "void inverse_dynamics_derivatives(const Scalar* q, const Scalar* v, const Scalar* qdd, const Scalar* lambda,\n"
     "                                  Workspace& w, Scalar* dtau_dq, Scalar* dtau_dv) noexcept",
     "// RNEA in world axes, then per (dof, dof of its path) pair the derivatives' entries.\n"},
    {Function::ForwardDynamicsDerivatives,
     "\n// forward_dynamics_derivatives (no constraint forces: the free motion):\n"
     "// qdd = M^-1 (tau - h) (ABA's answer, to round-off), and at (q, v, qdd)\n"
     "// dqdd_dq = -M^-1 dtau_dq, dqdd_dv = -M^-1 dtau_dv, dqdd_dtau = M^-1 (nv x nv each).\n"
     "// It calls nonlinear_effects, then the passes of mass_matrix_inverse and the tangent\n"
     "// sweep of inverse_dynamics_derivatives (held with it) on the kinematics it left in w.\n"
     "// None of the arrays may be inside w.\n",
     "void forward_dynamics_derivatives(const Scalar* q, const Scalar* v, const Scalar* tau, Workspace& w, Scalar* qdd,\n"
     "                                  Scalar* dqdd_dq, Scalar* dqdd_dv, Scalar* dqdd_dtau) noexcept",
     "// M^-1 by ABA on the unit torques, qdd = M^-1 (tau - h), the tangent sweep at qdd, two dense products.\n"},
    {Function::ConstrainedDynamicsDerivatives,
     "\n// constrained_dynamics_derivatives: qdd and lambda as prox_pv(q, v, tau, s) returns\n"
     "// them, and the derivatives of the solution prox_pv and constrained_aba converge\n"
     "// to with these Settings (the proximal limit: the minimum-norm multipliers where\n"
     "// J is rank-deficient) with respect to q (the tangent convention above), v and\n"
     "// tau: dqdd_* nv x nv, dlambda_* nc x nv. By the implicit function theorem on\n"
     "// M qdd + h + J^T lambda = tau, J qdd + gamma = a*, the multipliers' tangents by\n"
     "// s.iterations proximal steps with s.mu (as the solve: at K steps they are off\n"
     "// by what the K-th iterate is). A constraint with !s.active[k] counts as absent\n"
     "// (its rows are 0). It calls prox_pv, then the passes of mass_matrix_inverse and the\n"
     "// tangent sweep of inverse_dynamics_derivatives (held with it) on the kinematics\n"
     "// prox_pv left in w. None of the arrays may be inside w.\n",
     "void constrained_dynamics_derivatives(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s,\n"
     "                                      Workspace& w, Scalar* qdd, Scalar* lambda, Scalar* dqdd_dq,\n"
     "                                      Scalar* dqdd_dv, Scalar* dqdd_dtau, Scalar* dlambda_dq,\n"
     "                                      Scalar* dlambda_dv, Scalar* dlambda_dtau) noexcept",
     "// prox_pv, M^-1, the tangent sweep at (qdd, lambda), the constraint rows' derivatives\n"
     "// straight-line, then the dense algebra of the implicit function theorem.\n"},
};

// The declaration's signature: the schedule argument defaults to every
// constraint active (all_active), so calls without it keep compiling.
std::string withDefaultSchedule(std::string signature) {
  const std::string arg = "const bool* active";
  if (const std::size_t at = signature.find(arg); at != std::string::npos) signature.insert(at + arg.size(), " = all_active");
  return signature;
}

// constrained_dynamics_derivatives' dense algebra (docs/derivatives.md section
// 5): fixed bounds (template arguments), no branch on the data, no heap.
constexpr const char* kConstrainedDerivativeHelpers =
    "// A + shift I = L L^T (A n x n symmetric, row-major, its lower triangle read): L\n"
    "// lower triangular, its diagonal holding 1 / L_jj (what the solves multiply by),\n"
    "// its upper triangle zero. Not positive definite gives NaN, not a branch.\n"
    "template <int n>\n"
    "void dense_cholesky(const Scalar* A, Scalar shift, Scalar* L) noexcept {\n"
    "  for (int j = 0; j < n; ++j) {\n"
    "    Scalar d = A[j * n + j] + shift;\n"
    "    for (int k = 0; k < j; ++k) {\n"
    "      d -= L[j * n + k] * L[j * n + k];\n"
    "    }\n"
    "    const Scalar inv = Scalar(1) / std::sqrt(d);\n"
    "    L[j * n + j] = inv;\n"
    "    for (int i = j + 1; i < n; ++i) {\n"
    "      Scalar sum = A[i * n + j];\n"
    "      for (int k = 0; k < j; ++k) {\n"
    "        sum -= L[i * n + k] * L[j * n + k];\n"
    "      }\n"
    "      L[i * n + j] = sum * inv;\n"
    "      L[j * n + i] = Scalar(0);\n"
    "    }\n"
    "  }\n"
    "}\n\n"
    "// S_K = sum_(j = 1..K) mu^(1-j) (L L^T)^-j, the K proximal steps on the\n"
    "// multipliers' tangents as one operator (n x n, symmetric, row-major; L from\n"
    "// dense_cholesky). proximal_inverse: X = L^-1 (and Xt = X^T, scratch), then\n"
    "// A = X^T X = (L L^T)^-1; proximal_power: S := A + (A S) / mu, one step. A and\n"
    "// S are polynomials in the same matrix, so they commute and A S is symmetric:\n"
    "// each row i is formed from its diagonal on (n - i columns, a runtime row\n"
    "// kernel of that length: the *_rows templates recurse over i so that each\n"
    "// length is a constant) and mirrored; n^3 / 2 a step and about 2 n^3 / 3 for\n"
    "// A, where K steps of forward and back substitution from the identity take\n"
    "// K n^3.\n"
    "template <int n, int i = 0>\n"
    "void inverse_rows(const Scalar* PROXGEN_RT_RESTRICT L, Scalar* PROXGEN_RT_RESTRICT X,\n"
    "                  Scalar* PROXGEN_RT_RESTRICT Xt) noexcept {\n"
    "  if constexpr (i < n) {  // X's row i over [0, i]: (e_i - sum_(k < i) L_ik X_k) / L_ii; Xt = X^T\n"
    "    const int before[2] = {0, i};\n"
    "    Scalar r[i + 1];  // formed apart from X, whose earlier rows it reads\n"
    "    proxgen_rt::row_product<i + 1, n>(r, L + i * n, 1, X, Scalar(-1), before, 1);\n"
    "    r[i] = Scalar(1);\n"
    "    PROXGEN_RT_UNROLL\n"
    "    for (int c = 0; c <= i; ++c) {\n"
    "      X[i * n + c] = r[c] * L[i * n + i];\n"
    "      Xt[c * n + i] = X[i * n + c];\n"
    "    }\n"
    "    inverse_rows<n, i + 1>(L, X, Xt);\n"
    "  }\n"
    "}\n\n"
    "template <int n, int i = 0>\n"
    "void gram_rows(const Scalar* PROXGEN_RT_RESTRICT Xt, const Scalar* PROXGEN_RT_RESTRICT X,\n"
    "               Scalar* PROXGEN_RT_RESTRICT A) noexcept {\n"
    "  if constexpr (i < n) {  // A's row i over [i, n): sum_(k >= i) X_ki X_k (X_kj = 0 for j > k)\n"
    "    const int from[2] = {i, n};\n"
    "    proxgen_rt::row_product<n - i, n>(A + i * n + i, Xt + i * n, 1, X + i, Scalar(1), from, 1);\n"
    "    gram_rows<n, i + 1>(Xt, X, A);\n"
    "  }\n"
    "}\n\n"
    "template <int n, int i = 0>\n"
    "void power_rows(const Scalar* PROXGEN_RT_RESTRICT A, Scalar inv_mu, const Scalar* PROXGEN_RT_RESTRICT S,\n"
    "                Scalar* PROXGEN_RT_RESTRICT T) noexcept {\n"
    "  if constexpr (i < n) {  // T's row i over [i, n): A_i + sum_m (A_im / mu) S_m\n"
    "    static constexpr int all[2] = {0, n};\n"
    "    proxgen_rt::row_product<n - i, n>(T + i * n + i, A + i * n, 1, S + i, inv_mu, all, 1);\n"
    "    PROXGEN_RT_UNROLL\n"
    "    for (int c = i; c < n; ++c) {\n"
    "      T[i * n + c] += A[i * n + c];\n"
    "    }\n"
    "    power_rows<n, i + 1>(A, inv_mu, S, T);\n"
    "  }\n"
    "}\n\n"
    "// The upper triangle of U into both triangles of V (U may be V).\n"
    "template <int n>\n"
    "void mirror_upper(const Scalar* U, Scalar* V) noexcept {\n"
    "  for (int i = 0; i < n; ++i) {\n"
    "    for (int j = i; j < n; ++j) {\n"
    "      V[i * n + j] = U[i * n + j];\n"
    "      V[j * n + i] = U[i * n + j];\n"
    "    }\n"
    "  }\n"
    "}\n\n"
    "template <int n>\n"
    "void proximal_inverse(const Scalar* PROXGEN_RT_RESTRICT L, Scalar* PROXGEN_RT_RESTRICT X,\n"
    "                      Scalar* PROXGEN_RT_RESTRICT Xt, Scalar* PROXGEN_RT_RESTRICT A) noexcept {\n"
    "  // The rows read X's upper triangle: zeros.\n"
    "  for (int k = 0; k < n * n; ++k) X[k] = Scalar(0);\n"
    "  inverse_rows<n>(L, X, Xt);\n"
    "  gram_rows<n>(Xt, X, A);\n"
    "  mirror_upper<n>(A, A);\n"
    "}\n\n"
    "template <int n>\n"
    "void proximal_power(const Scalar* PROXGEN_RT_RESTRICT A, Scalar inv_mu, Scalar* PROXGEN_RT_RESTRICT T,\n"
    "                    Scalar* PROXGEN_RT_RESTRICT S) noexcept {\n"
    "  power_rows<n>(A, inv_mu, S, T);\n"
    "  mirror_upper<n>(T, S);\n"
    "}\n\n";

// Jr(e)^-1 for the 6d welds' Baumgarte position term (docs/derivatives.md section 2).
constexpr const char* kRightJacobianInverse =
    "// Jr(e)^-1 (6 x 6, row-major) of the SE(3) exponential at e = [linear; angular]:\n"
    "// log(Exp(e) Exp(x)) = e + Jr(e)^-1 x + O(x^2). Jr = sum_k (-ad_e)^k / (k + 1)!,\n"
    "// -ad_e = [[P, Q], [0, P]] (P = -[w]x, Q = -[rho]x), summed to a fixed 40 terms\n"
    "// (the remainder is below |ad_e|^41 / 42!, 1e-20 at |ad_e| = 6: round-off for\n"
    "// errors of metres and radians), then inverted by its block form:\n"
    "// [[A, B], [0, A]]^-1 = [[A^-1, -A^-1 B A^-1], [0, A^-1]]; A = Jr of SO(3) is\n"
    "// invertible for rotation errors below 2 pi.\n"
    "void se3_right_jacobian_inverse(const Scalar* e, Scalar* out) noexcept {\n"
    "  const Scalar P[9] = {0, e[5], -e[4], -e[5], 0, e[3], e[4], -e[3], 0};\n"
    "  const Scalar Q[9] = {0, e[2], -e[1], -e[2], 0, e[0], e[1], -e[0], 0};\n"
    "  Scalar Pk[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Ck[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};\n"
    "  Scalar A[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, B[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};\n"
    "  Scalar f = 1;\n"
    "  for (int t = 1; t < 41; ++t) {\n"
    "    f = f / Scalar(t + 1);\n"
    "    Scalar nP[9], nC[9];\n"
    "    for (int i = 0; i < 3; ++i) {\n"
    "      for (int j = 0; j < 3; ++j) {\n"
    "        Scalar sp = 0, sc = 0;\n"
    "        for (int k = 0; k < 3; ++k) {\n"
    "          sp += P[3 * i + k] * Pk[3 * k + j];\n"
    "          sc += P[3 * i + k] * Ck[3 * k + j] + Q[3 * i + k] * Pk[3 * k + j];\n"
    "        }\n"
    "        nP[3 * i + j] = sp;\n"
    "        nC[3 * i + j] = sc;\n"
    "      }\n"
    "    }\n"
    "    for (int i = 0; i < 9; ++i) {\n"
    "      Pk[i] = nP[i];\n"
    "      Ck[i] = nC[i];\n"
    "      A[i] += f * Pk[i];\n"
    "      B[i] += f * Ck[i];\n"
    "    }\n"
    "  }\n"
    "  const Scalar c0 = A[4] * A[8] - A[5] * A[7], c1 = A[5] * A[6] - A[3] * A[8], c2 = A[3] * A[7] - A[4] * A[6];\n"
    "  const Scalar inv_det = Scalar(1) / (A[0] * c0 + A[1] * c1 + A[2] * c2);\n"
    "  const Scalar adj[9] = {c0, A[2] * A[7] - A[1] * A[8], A[1] * A[5] - A[2] * A[4],\n"
    "                        c1, A[0] * A[8] - A[2] * A[6], A[2] * A[3] - A[0] * A[5],\n"
    "                        c2, A[1] * A[6] - A[0] * A[7], A[0] * A[4] - A[1] * A[3]};\n"
    "  Scalar Ai[9], T[9];\n"
    "  for (int i = 0; i < 9; ++i) {\n"
    "    Ai[i] = adj[i] * inv_det;\n"
    "  }\n"
    "  for (int i = 0; i < 3; ++i) {\n"
    "    for (int j = 0; j < 3; ++j) {\n"
    "      T[3 * i + j] = B[3 * i] * Ai[j] + B[3 * i + 1] * Ai[3 + j] + B[3 * i + 2] * Ai[6 + j];\n"
    "    }\n"
    "  }\n"
    "  for (int i = 0; i < 3; ++i) {\n"
    "    for (int j = 0; j < 3; ++j) {\n"
    "      out[6 * i + j] = Ai[3 * i + j];\n"
    "      out[6 * (i + 3) + j + 3] = Ai[3 * i + j];\n"
    "      out[6 * (i + 3) + j] = Scalar(0);\n"
    "      out[6 * i + j + 3] = -(Ai[3 * i] * T[j] + Ai[3 * i + 1] * T[3 + j] + Ai[3 * i + 2] * T[6 + j]);\n"
    "    }\n"
    "  }\n"
    "}\n\n";

// The helpers the part functions call (before them), printed only when one needs them.
std::string partHelpers(const System& sys, const SolverTexts& texts) {
  bool gains6 = false;
  for (const Constraint& c : sys.constraints) gains6 |= c.type == ConstraintType::Weld6D && c.kp != 0;
  return texts.functions.has(Function::ConstrainedDynamicsDerivatives) && gains6 ? kRightJacobianInverse : "";
}

// The helpers the entry points call, printed only when one needs them.
std::string helpers(const SolverTexts& texts) {
  std::string out;
  // "<comment lines>void <signature> noexcept {<body>}", where `wanted`.
  const auto helper = [&](bool wanted, const char* comment, const char* signature, const std::string& body) {
    if (wanted) out += fmt::format("{}void {} noexcept {{\n{}}}\n\n", comment, signature, body);
  };
  helper(texts.withKinematics,
         "// Joint transforms, body velocities v, velocity-product accelerations c, bias\n"
         "// forces pA = v x* I v, gravity in the support bodies, constraint right-hand sides k.\n",
         "kinematics(const Scalar* q, const Scalar* v, Workspace& w)", texts.kinematics);
  helper(texts.withJointTransforms, "// The joint transforms alone, for the functions without a velocity.\n",
         "joint_transforms(const Scalar* q, Workspace& w)", texts.jointTransforms);
  const bool cdd = texts.functions.has(Function::ConstrainedDynamicsDerivatives);
  if (texts.functions.has(Function::ForwardDynamicsDerivatives) || cdd)
    out += "// C += s A B, A n x m, B m x p, C n x p, all row-major (the derivatives' dense\n"
           "// products: fixed bounds, no branch on the data; C may not overlap A or B).\n"
           "// Row by row, C's row plus a sum of B's rows, each entry adding its terms in the\n"
           "// order of k; the runtime's row_madd holds the row in vector registers over k.\n"
           "// B's and C's rows are ldb and ldc apart (blocks of wider matrices).\n"
           "template <int n, int m, int p, int ldb = p, int ldc = p>\n"
           "void dense_product_add(const Scalar* PROXGEN_RT_RESTRICT A, const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                       Scalar* PROXGEN_RT_RESTRICT C) noexcept {\n"
           "  static constexpr int all[2] = {0, m};\n"
           "  for (int r = 0; r < n; ++r) {\n"
           "    proxgen_rt::row_madd<p, ldb>(C + r * ldc, A + r * m, 1, B, s, all, 1);\n"
           "  }\n"
           "}\n\n"
           "// C = s A B (as dense_product_add, from C = 0).\n"
           "template <int n, int m, int p, int ldb = p, int ldc = p>\n"
           "void dense_product(const Scalar* PROXGEN_RT_RESTRICT A, const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                   Scalar* PROXGEN_RT_RESTRICT C) noexcept {\n"
           "  static constexpr int all[2] = {0, m};\n"
           "  for (int r = 0; r < n; ++r) {\n"
           "    proxgen_rt::row_product<p, ldb>(C + r * ldc, A + r * m, 1, B, s, all, 1);\n"
           "  }\n"
           "}\n\n"
           "// The same products where one factor has zeros the emitter knows (the tree's\n"
           "// pattern): a row's nonzero entries are the ranges [span[2 j], span[2 j + 1]),\n"
           "// j from start[row] to start[row + 1], and nothing outside them is read. Each\n"
           "// entry adds the same terms in the same order as the dense loop, less the zeros.\n"
           "// C += s A B, A's row r nonzero only in its ranges of k.\n"
           "template <int n, int m, int p, int ldb = p, int ldc = p>\n"
           "void sparse_left_product_add(const Scalar* PROXGEN_RT_RESTRICT A, const int* start, const int* span,\n"
           "                             const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                             Scalar* PROXGEN_RT_RESTRICT C) noexcept {\n"
           "  for (int r = 0; r < n; ++r) {\n"
           "    proxgen_rt::row_madd<p, ldb>(C + r * ldc, A + r * m, 1, B, s, span + 2 * start[r], start[r + 1] - start[r]);\n"
           "  }\n"
           "}\n\n"
           "// C = s A^T B, A m x n, B m x p, C n x p: A^T's row r (A's column r) nonzero only\n"
           "// in its ranges of k. With A's transpose on the left the sum still runs over\n"
           "// B's full rows (fixed bounds), as in dense_product_add. A's, B's and C's rows\n"
           "// are lda, ldb and ldc apart.\n"
           "template <int n, int m, int p, int lda = n, int ldb = p, int ldc = p>\n"
           "void sparse_transposed_product(const Scalar* PROXGEN_RT_RESTRICT A, const int* start, const int* span,\n"
           "                               const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                               Scalar* PROXGEN_RT_RESTRICT C) noexcept {\n"
           "  for (int r = 0; r < n; ++r) {\n"
           "    proxgen_rt::row_product<p, ldb>(C + r * ldc, A + r, lda, B, s, span + 2 * start[r], start[r + 1] - start[r]);\n"
           "  }\n"
           "}\n\n"
           "// C += s A^T B (as sparse_transposed_product, into C).\n"
           "template <int n, int m, int p, int lda = n, int ldb = p, int ldc = p>\n"
           "void sparse_transposed_product_add(const Scalar* PROXGEN_RT_RESTRICT A, const int* start, const int* span,\n"
           "                                   const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                                   Scalar* PROXGEN_RT_RESTRICT C) noexcept {\n"
           "  for (int r = 0; r < n; ++r) {\n"
           "    proxgen_rt::row_madd<p, ldb>(C + r * ldc, A + r, lda, B, s, span + 2 * start[r], start[r + 1] - start[r]);\n"
           "  }\n"
           "}\n\n";
  if (cdd)
    out += kConstrainedDerivativeHelpers;
  helper(!texts.minvForward.empty(),
         "// mass_matrix_inverse's forward pass: the unit-torque accelerations from what either\n"
         "// backward pass (mass_matrix_inverse_passes, mass_matrix_inverse_factored) left in w.\n",
         "mass_matrix_inverse_forward(Workspace& w, Scalar* Minv)", texts.minvForward);
  helper(!texts.minvPasses.empty(),
         "// mass_matrix_inverse after the joint transforms: ABA on the unit torques; reads the\n"
         "// joint transforms in w (joint_transforms or kinematics of the same q wrote them).\n",
         "mass_matrix_inverse_passes(const Scalar* q, Workspace& w, Scalar* Minv)", texts.minvPasses);
  helper(!texts.minvFactored.empty(),
         "// The same after prox_pv of the same q: reads its elimination's U and D^-1 (and the\n"
         "// free flyer's Cholesky factor) in w instead of forming them again.\n",
         "mass_matrix_inverse_factored(const Scalar* q, Workspace& w, Scalar* Minv)", texts.minvFactored);
  if (!texts.tangentSweep.empty())
    out += "// The world-frame sweep's pairs (docs/derivatives.md section 5): its per-dof arrays are\n"
           "// [6][n] (BS: [3][n]), column k dof k's vector. Rows: for every dof c and every dof r\n"
           "// whose path holds c (the dofs of c's joint's subtree, its own joint's included:\n"
           "// [rows[2 c], rows[2 c + 1])), out[r][c] = IS_r . A_c + s BS_r . B_c, B's angular rows;\n"
           "// dtau_dq is (A, B, s) = (C, U, -1), dtau_dv (W, S, +1). Columns: for every dof c and\n"
           "// every dof r of its joint's strict subtree ([span[2 c], span[2 c + 1])), dq[c][r] =\n"
           "// S_c . Pq_r and dv[c][r] = S_c . Pv_r. Inner loops over contiguous dofs, reading IS, BS,\n"
           "// Pq and Pv along their rows; fixed tables, no branch on the data.\n"
           "template <int n>\n"
           "void world_frame_rows(const Scalar* PROXGEN_RT_RESTRICT IS, const Scalar* PROXGEN_RT_RESTRICT BS,\n"
           "                      const Scalar* PROXGEN_RT_RESTRICT A, const Scalar* PROXGEN_RT_RESTRICT B, Scalar s,\n"
           "                      const int* rows, Scalar* PROXGEN_RT_RESTRICT out) noexcept {\n"
           "  for (int c = 0; c < n; ++c) {\n"
           "    Scalar a[6], b[3];\n"
           "    for (int k = 0; k < 6; ++k) a[k] = A[k * n + c];\n"
           "    // s = +-1: (s x) y = x (s y), exactly.\n"
           "    for (int k = 0; k < 3; ++k) b[k] = s * B[(3 + k) * n + c];\n"
           "    for (int r = rows[2 * c]; r < rows[2 * c + 1]; ++r) {\n"
           "      out[r * n + c] = IS[r] * a[0] + IS[n + r] * a[1] + IS[2 * n + r] * a[2] + IS[3 * n + r] * a[3] +\n"
           "                       IS[4 * n + r] * a[4] + IS[5 * n + r] * a[5] +\n"
           "                       (BS[r] * b[0] + BS[n + r] * b[1] + BS[2 * n + r] * b[2]);\n"
           "    }\n"
           "  }\n"
           "}\n\n"
           "template <int n>\n"
           "void world_frame_columns(const Scalar* PROXGEN_RT_RESTRICT S, const Scalar* PROXGEN_RT_RESTRICT Pq,\n"
           "                         const Scalar* PROXGEN_RT_RESTRICT Pv, const int* span, Scalar* PROXGEN_RT_RESTRICT dq,\n"
           "                         Scalar* PROXGEN_RT_RESTRICT dv) noexcept {\n"
           "  for (int c = 0; c < n; ++c) {\n"
           "    Scalar s[6];\n"
           "    for (int k = 0; k < 6; ++k) s[k] = S[k * n + c];\n"
           "    for (int r = span[2 * c]; r < span[2 * c + 1]; ++r) {\n"
           "      dq[c * n + r] = s[0] * Pq[r] + s[1] * Pq[n + r] + s[2] * Pq[2 * n + r] + s[3] * Pq[3 * n + r] +\n"
           "                      s[4] * Pq[4 * n + r] + s[5] * Pq[5 * n + r];\n"
           "      dv[c * n + r] = s[0] * Pv[r] + s[1] * Pv[n + r] + s[2] * Pv[2 * n + r] + s[3] * Pv[3 * n + r] +\n"
           "                      s[4] * Pv[4 * n + r] + s[5] * Pv[5 * n + r];\n"
           "    }\n"
           "  }\n"
           "}\n\n";
  helper(!texts.tangentSweep.empty(),
         "// inverse_dynamics_derivatives after the kinematics pass: RNEA at (qdd, lambda) in world\n"
         "// axes and its derivatives along every q and v direction; reads the joint transforms,\n"
         "// v and c in w.\n",
         "tangent_sweep(const Scalar* q, const Scalar* v, const Scalar* qdd, const Scalar* lambda, Workspace& w,\n"
         "                   Scalar* dtau_dq, Scalar* dtau_dv)",
         texts.tangentSweep);
  helper(!texts.constraintJoints.empty(), "// Joint transforms, for the constraint functions of q alone.\n",
         "constraint_joints(const Scalar* q, Workspace& w)", texts.constraintJoints);
  return out;
}

std::string bodyOf(const SolverTexts& texts, Function f) {
  if (f == Function::ConstrainedAba) return texts.caba;
  if (f == Function::ProxPv) return texts.pv;
  return texts.library.at(f);
}

// The names and slots of the header (docs/design.md, "Names in the generated
// files"): string arrays of the raw names, slot arrays, and an index per joint
// and per constraint under its sanitised identifier.
struct Names {
  std::string jointNames, jointQ, jointV, jointIds, consNames, consRow, consRows, consIds, empty;
};
Names namesAndSlots(const Plan& plan) {
  Names n;
  IdentifierSet jointIds;  // joints have no identifier in the plan: made here, unique by position
  const auto sep = [](const std::string& s) { return s.empty() ? "" : ", "; };
  for (std::size_t i = 1; i < plan.bodies.size(); ++i) {
    const BodyPlan& b = plan.bodies[i];
    const int k = int(i) - 1;
    n.jointNames += sep(n.jointNames) + cStringLiteral(b.joint);
    n.jointQ += fmt::format("{}{}", sep(n.jointQ), b.idx_q);
    n.jointV += fmt::format("{}{}", sep(n.jointV), b.idx_v);
    n.jointIds += fmt::format("inline constexpr int {} = {};\n", jointIds.make(b.joint, k), k);
  }
  for (std::size_t k = 0; k < plan.constraints.size(); ++k) {
    const ConstraintPlan& c = plan.constraints[k];
    n.consNames += sep(n.consNames) + cStringLiteral(c.name);
    n.consRow += fmt::format("{}{}", sep(n.consRow), c.row);
    n.consRows += fmt::format("{}{}", sep(n.consRows), c.rows);
    n.consIds += fmt::format("inline constexpr int {} = {};\n", c.ident, k);
  }
  // A C++ array cannot be empty: one placeholder entry, said so.
  if (n.jointNames.empty()) {
    n.jointNames = "nullptr", n.jointQ = n.jointV = "0";
    n.empty += "\n// No joints: the joint arrays hold one placeholder entry (nullptr, 0).";
  }
  if (n.consNames.empty()) {
    n.consNames = "nullptr", n.consRow = n.consRows = "0";
    n.empty += "\n// No constraints (ncons = 0): the constraint arrays hold one placeholder entry (nullptr, 0).";
  }
  return n;
}

// Every constraint active by default: "true, true, ..." (one placeholder without constraints).
std::string activeInit(const Plan& plan) {
  std::string init = "true";
  for (std::size_t k = 1; k < plan.constraints.size(); ++k) init += ", true";
  return init;
}

// major.minor of PROXGEN_VERSION ("0.1.0").
std::pair<int, int> versionNumbers() {
  int major = 0, minor = 0;
  if (std::sscanf(PROXGEN_VERSION, "%d.%d", &major, &minor) != 2) throw std::logic_error("PROXGEN_VERSION is not major.minor");
  return {major, minor};
}

}  // namespace

const std::vector<std::string>& fileFunctionNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out = {"kinematics", "joint_transforms", "constraint_joints", "eliminate_free_bodies",
                                    "accelerate_free_bodies", "tangent_sweep", "world_frame_rows", "world_frame_columns", "mass_matrix_inverse_passes",
                                    "mass_matrix_inverse_factored", "mass_matrix_inverse_forward",
                                    "residual",
                                    "dense_product", "dense_product_add", "sparse_left_product_add",
                                    "sparse_transposed_product", "sparse_transposed_product_add", "dense_cholesky", "inverse_rows",
                                    "gram_rows", "power_rows", "mirror_upper", "proximal_inverse", "proximal_power",
                                    "se3_right_jacobian_inverse"};
    for (Function f : allFunctions()) out.push_back(functionName(f));
    return out;
  }();
  return names;
}

SolverFiles assembleFiles(const System& sys, const Plan& plan, const SolverInputs& in, const Members& ws,
                          const SolverTexts& texts) {
  const Model& m = sys.model;
  const int scalarBytes = plan.scalar == ScalarType::Float ? 4 : 8;

  std::string joints;
  for (int i = 1; i < m.numBodies(); ++i) {
    const BodyPlan& b = plan.bodies[std::size_t(i)];
    joints += fmt::format("//   q[{}..{}] v[{}..{}]  joint '{}' ({}), link '{}'\n", b.idx_q, b.idx_q + b.nq - 1, b.idx_v,
                          b.idx_v + b.nv - 1, escapeComment(b.joint), jointClassName(b.jointClass), escapeComment(b.link));
  }
  std::string constraints;
  for (const ConstraintPlan& c : plan.constraints)
    constraints += fmt::format("//   lambda[{}..{}]  '{}' ({}) on link '{}'\n", c.row, c.row + c.rows - 1, escapeComment(c.name),
                               c.weld ? "6d weld" : "3d point contact", escapeComment(c.link));
  if (constraints.empty()) constraints = "//   (none)\n";

  std::string operations, declarations, definitions;
  for (const EntryPoint& ep : kEntryPoints) {
    if (!texts.functions.has(ep.f)) continue;
    const OpCount ops = ep.f == Function::ConstrainedAba ? texts.cabaOps
                        : ep.f == Function::ProxPv       ? texts.pvOps
                                                         : texts.libraryOps.at(ep.f);
    operations += opLine(functionName(ep.f), ops, plan.iterations);
    // prox_pv alone takes constrained_aba's comment
    declarations += std::string(ep.f == Function::ProxPv && !texts.functions.has(Function::ConstrainedAba)
                                    ? kEntryPoints[0].header
                                    : ep.header) +
                    withDefaultSchedule(ep.signature) + ";\n";
    definitions += fmt::format("{}{} {{\n{}}}\n\n", ep.source, ep.signature, bodyOf(texts, ep.f));
  }
  // residual(w): the last solve's, so only with a solver.
  if (texts.functions.has(Function::ConstrainedAba) || texts.functions.has(Function::ProxPv)) {
    declarations +=
        "\n// ||J qdd + gamma - a*||_inf of the last solve with w (qdd its output, a* the\n"
        "// layout's Baumgarte target, rows as lambda): how far the K-th iterate is from\n"
        "// satisfying the constraints, to choose K by accuracy. NaN if a row is not\n"
        "// finite; 0 without constraints.\n"
        "Scalar residual(const Workspace& w) noexcept;\n";
    definitions += fmt::format("// The largest row of K a - k, stored by the last solve.\n"
                               "Scalar residual(const Workspace& w) noexcept {{\n{}}}\n\n",
                               plan.nc > 0 ? "  return proxgen_rt::largest_magnitude_of<nc>(w.residual);\n"
                                           : "  static_cast<void>(w);\n  return Scalar(0);\n");
  }
  // Which blocks were shared (issue 20: say which subtrees share their code).
  std::string shared;
  if (!texts.sharedKernels.empty()) {
    shared = "// Shared blocks (docs/emitter.md): each kernel below runs the blocks that are the\n"
             "// same code up to their constants, over a table of each one's constants; two\n"
             "// blocks \"in pairs\" run as one call, one in each lane of a vector register:\n";
    for (const SharedKernel& k : texts.sharedKernels)
      shared += fmt::format("//   {}: {} blocks of {}{}\n", k.name, k.blocks.size(), fmt::join(k.bodies, ", "),
                            k.signs > 0   ? fmt::format(" ({} in pairs, mirrored: {} signs turned in one lane)",
                                                        2 * k.pairs, k.signs)
                            : k.pairs > 0 ? fmt::format(" ({} in pairs)", 2 * k.pairs)
                                          : "");
  }
  auto bannerWith = [&](const std::string& sharedLines) {
    return fmt::format(fmt::runtime(kBannerTemplate), fmt::arg("version", PROXGEN_VERSION),
                       fmt::arg("urdf", escapeComment(in.urdfName)), fmt::arg("layout", escapeComment(in.layoutName)),
                       fmt::arg("command", escapeComment(in.command)), fmt::arg("robot", escapeComment(m.name)),
                       fmt::arg("urdf_sha", in.urdfSha256), fmt::arg("layout_sha", in.layoutSha256),
                       fmt::arg("operations", operations + sharedLines));
  };
  const std::string banner = bannerWith(shared);

  SolverFiles files;
  files.headerName = plan.name + ".hpp";
  files.sourceName = plan.name + ".cpp";
  const CodeBuilder lit(plan.scalar);
  const Names n = namesAndSlots(plan);
  const auto [major, minor] = versionNumbers();
  files.header = fmt::format(
      fmt::runtime(kHeaderTemplate), fmt::arg("banner", banner),
      fmt::arg("q_convention", plan.qConvention),
      fmt::arg("joint_table", joints), fmt::arg("constraint_table", constraints), fmt::arg("name", plan.name),
      fmt::arg("scalar", scalarName(plan.scalar)), fmt::arg("nq", plan.nq), fmt::arg("nv", plan.nv),
      fmt::arg("nc", plan.nc), fmt::arg("mu", lit.literal(plan.mu)), fmt::arg("iterations", plan.iterations),
      fmt::arg("workspace_bytes", ws.scalars() * scalarBytes), fmt::arg("members", ws.declarations()),
      fmt::arg("declarations", declarations), fmt::arg("ncons", plan.constraints.size()),
      fmt::arg("version", PROXGEN_VERSION), fmt::arg("version_major", major), fmt::arg("version_minor", minor),
      fmt::arg("empty_arrays", n.empty), fmt::arg("joint_names", n.jointNames), fmt::arg("joint_idx_q", n.jointQ),
      fmt::arg("joint_idx_v", n.jointV), fmt::arg("joint_ids", n.jointIds), fmt::arg("constraint_names", n.consNames),
      fmt::arg("constraint_row", n.consRow), fmt::arg("constraint_rows", n.consRows),
      fmt::arg("constraint_ids", n.consIds), fmt::arg("active_size", std::max<std::size_t>(plan.constraints.size(), 1)),
      fmt::arg("active_init", activeInit(plan)),
      fmt::arg("active_note", plan.constraints.empty() ? "\n  // No constraints: one placeholder entry, never read." : ""));
  auto source = [&](const std::string& parts, const std::string& sourceBanner) {
    return fmt::format(fmt::runtime(kSourceTemplate), fmt::arg("banner", sourceBanner), fmt::arg("name", plan.name),
                       fmt::arg("parts", parts), fmt::arg("helpers", helpers(texts)),
                       fmt::arg("part_helpers", partHelpers(sys, texts)), fmt::arg("free_bodies", freeBodies(texts)),
                       fmt::arg("definitions", definitions));
  };
  files.source = source(texts.parts, banner);
  files.unsharedSource = texts.sharedKernels.empty() ? files.source : source(texts.unsharedParts, bannerWith(""));
  CInterfaceFiles c = emitCInterface(plan, texts.functions, banner, ws.scalars() * scalarBytes);
  files.cHeaderName = std::move(c.headerName), files.cHeader = std::move(c.header);
  files.cSourceName = std::move(c.sourceName), files.cSource = std::move(c.source);
  return files;
}

}  // namespace proxgen::emit

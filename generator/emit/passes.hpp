// The passes of the emitter, one file each (pass_<name>.cpp), as
// generator/algorithms/ has one file per recursion. A pass prints the blocks
// of one recursion into the function being written (Emit::fn) and returns what
// later passes read (body_state.hpp). The entry points (constrained_aba,
// prox_pv) are compositions of these calls; emitter.cpp is the list of
// functions of a solver. docs/emitter.md: how to add one.
#pragma once

#include <array>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "emit/context.hpp"

namespace proxgen::emit {

// ---- pass_kinematics.cpp: joint transforms, v, c, pA = v x* I v, R^T g,
// world placements, the constraint right-hand sides k.
Kinematics emitKinematics(Emit& e);
/// One body's joint placement X_J(q), its motion subspace and tree placement.
void jointTransform(Emit& e, int i, Kinematics::Body& b);
/// Whether jointTransform calls the runtime's sincos (sincos_joint_called) rather
/// than inlining it: on a robot of more than kSincosInlinedUpTo revolute joints.
/// The called form's run computes the sines and cosines in two lanes at the
/// x86-64 baseline (lanes.hpp), and with it the called form is faster than the
/// inlined one on every shared case there (bench/ab_compare.sh: Solo's proxPV
/// 0.90-0.92 of the time, its inverse_dynamics 0.93, the iiwa's 0.96-0.99, with
/// fewer instructions) and the same with AVX-512 (0.99-1.01): docs/benchmarks.md,
/// "The called form from five revolute joints". Without the run (the first
/// measurements, docs/benchmarks.md "sincos called on the larger robots") only
/// the robots past 16 joints gained.
inline constexpr std::size_t kSincosInlinedUpTo = 4;
bool sincosCalled(const Plan& plan);
/// Before the joint transforms of every body (`supportOnly`: of the bodies on
/// the constraints' support): their revolute joints' sines and
/// cosines, one proxgen_rt::sincos_run per run of consecutive angles in q
/// (w.sq and w.cq, slot j for the j-th revolute joint in q order). It computes
/// them where the target has 4 or more double lanes, and with 2 (x86-64's SSE2)
/// where the joints call sincos (sincosCalled: `sincos_run<N, true>`); elsewhere
/// it is empty and each joint's sincos_joint(_called) computes its own
/// (lanes.hpp). Every pass that calls jointTransform calls this first
/// (jointTransformsFirst does).
void sincosRuns(Emit& e, bool supportOnly = false);
/// The sincos runs of every body (sincosRuns), then, where sincos is inlined,
/// a pass of every body's joint transform into kin
/// (true), which the sweep that follows then reads; else nothing (false) and
/// each body's step computes its own (docs/benchmarks.md: the faster way for each).
bool jointTransformsFirst(Emit& e, Kinematics& kin);
/// pA = v x* (I v) of body i from b.v and b.IA, into its member (the kinematics pass).
void storeBiasForce(Emit& e, int i, Kinematics::Body& b);
// A weld's placement error e = log6(target^-1 oMc) through the runtime's log6,
// printed as `<prefix>R_<id>[9]`, `<prefix>p_<id>[3]` -> `<prefix>e_<id>[6]`;
// returns the six entries of e (the kinematics pass's Baumgarte term and the
// constrained derivatives' right Jacobian read it).
std::vector<Expr> weldError(CodeBuilder& cb, const XSym& oMc, const Constraint& c, const std::string& prefix,
                            const std::string& id);

// ---- pass_aba_eliminate.cpp: the articulated-body elimination.
/// The elimination's starting point: every body's own inertia and bias.
Articulated startElimination(const Kinematics& kin);
/// One body: U, D^-1, u, and (below the root) its share of the parent's IA and
/// pA. With `k`, the penalty mu K^T K of the body's constraints first (constrainedABA).
/// Without `bias`, IA, U and D only (no tau, u, pA: the Delassus functions).
void eliminateBody(Emit& e, const Kinematics& kin, int i, const std::vector<std::vector<Expr>>* k, Articulated& art,
                   bool bias = true);
/// A planar joint's U = IA S (the three columns of IA that pickedComponents
/// picks) and the factor of D = S^T U = L L^T, into body i's members and b.
void factorPicked(Emit& e, int i, const Sym& IA, Articulated::Body& b);
/// IA - U D^-1 U^T for that joint (b's U and factor), its rows and columns sel
/// exactly zero (Ia S = 0), flattened: what passes on to the parent.
Sym reducedPicked(CodeBuilder& cb, const Sym& IA, const Articulated::Body& b, const std::vector<int>& sel);
/// The bodies off the constraint support, leaves first (the same in both algorithms).
Articulated eliminateFreeBodies(Emit& e, const Kinematics& kin);

// ---- pass_aba_accelerate.cpp: the forward pass.
/// a'_i = X_i a_p + c_i ; qdd_i = D^-1 (uEff - U^T a'_i) ; a_i = a'_i + S qdd_i.
void accelerateBody(Emit& e, const Kinematics& kin, const Articulated& art, int i, const std::vector<Expr>& uEff,
                    bool storeQdd, Motion& motion);
/// The support bodies in tree order, with their u.
void accelerateSupport(Emit& e, const Kinematics& kin, const Articulated& art, Motion& motion);
/// The off-support bodies: printed once as accelerate_free_bodies (from the
/// first caller's state), called by both algorithms; their qdd come back into `motion`.
struct FreeAccelerations {
  std::string text;                    // the function's body
  std::string supportAccelerations;    // what it reads, to check the second caller
  const CodeBuilder* builder = nullptr;
  Motion out;
};
void callAccelerateFree(Emit& e, const Kinematics& kin, const Articulated& art, Motion& motion);

// ---- pass_dense_factor.cpp: dense Cholesky and triangular solves, unrolled.
struct Cholesky {
  Sym L;
  std::vector<Expr> inv;  // 1 / diag(L)
};
/// (A + shift I) = L L^T, L's entries stored to Lname(i, j), 1 / L(j, j) to invName(j).
Cholesky cholesky(Emit& e, const Sym& A, const Expr& shift, const std::function<std::string(int, int)>& Lname,
                  const std::function<std::string(int)>& invName);
std::vector<Expr> forwardSolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b);
std::vector<Expr> backwardSolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& y);
/// (L L^T)^-1 b: the two solves.
std::vector<Expr> choleskySolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b);

// ---- pass_constrained_aba.cpp: the constrained_aba entry point (body text);
// kin and art are its own copies of the state after eliminate_free_bodies,
// whose values live in `from`.
/// The run-time schedule (Settings::active, docs/algorithms.md §4.4): the host
/// writes w.active[k] = Scalar(flags[k]) for every constraint k (`flags`: the
/// raw text of the bool array, "s.active" or "active"); activeFactor reads it
/// back as a 0/1 factor in any function after that.
void storeActiveFactors(Emit& e, const std::string& flags);
Expr activeFactor(Emit& e, int k);
/// The constraint (layout order) of row `row` (layout numbering), and its factor.
int rowConstraint(const Plan& plan, int row);
Expr activeRowFactor(Emit& e, int row);
/// qdd and lambda out of the workspace (the end of both entry points).
void copyOut(Emit& e, const Motion& motion, const Multipliers& mult);
/// The warm start in the host: lambda = s.lambda0 (or 0; 0 for the rows of an
/// inactive constraint, whose lambda0 is never read); and the member of
/// the rows' residual K a - k that residual(w) reads (both entry points).
void startMultipliers(Emit& e, Multipliers& mult);
std::string residualMember(Emit& e, int row);
std::string emitConstrainedAba(Emit& e, Kinematics kin, Articulated art, const CodeBuilder* from);

// ---- pass_prox_pv.cpp: the prox_pv entry point (body text), as above.
/// What prox_pv leaves in the workspace for a caller of the same (q, v):
/// the kinematics state and its elimination's factors (U, D^-1, the free
/// flyer's and planar joints' Cholesky factors), as values of `host`.
struct ProxPvEnd {
  Kinematics kin;
  Articulated art;
  const CodeBuilder* host = nullptr;
};
std::string emitProxPv(Emit& e, Kinematics kin, Articulated art, const CodeBuilder* from, ProxPvEnd* end = nullptr);
/// rows.b[i].KA = K_i^T: body i's own rows (layout order) as force directions
/// in its coordinates, the start of every pass that carries rows up the tree.
void initOwnRows(Emit& e, int i, ProxRows& rows);

// ---- pass_delassus_factor.cpp: G + I/mu from proxPV's rows, factored; solves.
DelassusFactor factorDelassus(Emit& e, const ProxRows& rows);
/// (G + I/mu)^-1 rhs through the factor (rows in tree order).
std::vector<Expr> solveDelassus(Emit& e, const DelassusFactor& f, const std::vector<Expr>& rhs);

// ---- pass_inverse_dynamics.cpp: RNEA with the constraint forces J^T lambda.
/// The inverse_dynamics host (nonlinear_effects: qdd = 0, no lambda), from its
/// copy of the state after kinematics, whose values live in `afterKinematics`.
std::string emitInverseDynamics(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics, bool nonlinearEffects);
/// f += K_c^T lambda_c for each constraint c on body i: its rows (lambda[row])
/// as a wrench at its frame (also the derivatives' sweep).
void addConstraintForces(Emit& e, int i, V6& f);

// ---- column_loops.cpp: a run of adjacent columns of one shape as one loop over j.
/// Runs of fewer columns than this stay unrolled: a loop of one column is only
/// overhead (proxPV's carried columns use the same threshold).
inline constexpr int kShortestColumnLoop = 2;
/// `PROXGEN_RT_NO_UNROLL for (int j = 0; j < len; ++j) {`: the head of every column loop.
std::string columnLoopHead(int len);
/// The runs of `ks` (sorted columns): adjacent columns for which `joins(k, k0)`
/// holds with the run's first, as (first, length); runs shorter than
/// kShortestColumnLoop are split into single columns.
std::vector<std::pair<int, int>> columnRuns(const std::vector<int>& ks, const std::function<bool(int, int)>& joins);
/// Starts a part and opens a run's block: `for (int j = 0; j < len; ++j) {`, or a plain block for one column.
void openColumns(Emit& e, const std::string& ident, int k0, int len, const std::string& label);
/// Columns k and k0 have entries of one shape (inputs(k): column k's entries):
/// each entry the same constant in both, or +-(a member slot) whose index
/// advances by one per column (FA_p[r][j], minv[idx(s, j)]).
bool oneShape(const CodeBuilder& cb, const std::function<std::vector<Expr>(int)>& inputs, int k, int k0);
/// A loop's reading of a column's entries: column k0's, indexed [idx + j].
std::vector<Expr> loopReads(CodeBuilder& cb, const std::vector<Expr>& first);
std::vector<Expr> entries(const V6& x);
V6 toV6(const std::vector<Expr>& x, std::size_t from = 0);

// ---- pass_mass_matrix.cpp: the joint transforms alone, and CRBA.
/// joint_transforms(q, w): X_J and the bodies' own inertias, for the functions without v.
Kinematics emitJointTransforms(Emit& e);
std::string emitMassMatrix(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms);

// ---- pass_mass_matrix_inverse.cpp: M^-1 in O(n^2) (ABA on the unit torques).
/// The body of mass_matrix_inverse_passes(q, w, Minv), which reads the joint
/// transforms in the workspace: mass_matrix_inverse is joint_transforms(q, w)
/// and this; the derivative functions call it after a kinematics pass of the
/// same q, which writes the same transforms. With `eliminated` (prox_pv's
/// elimination at the same q, ProxPvEnd), the body of
/// mass_matrix_inverse_factored(q, w, Minv): its backward pass reads U and
/// D^-1 from it instead of forming them and the articulated inertias again.
/// Both end with mass_matrix_inverse_forward(w, Minv), whose body is returned
/// in `forwardText` when given (printed once, for either variant).
std::string emitMassMatrixInverse(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms,
                                  const Articulated* eliminated = nullptr, std::string* forwardText = nullptr);

// ---- pass_constraint_kinematics.cpp: constraint_placements, constraint_jacobian,
// constraint_drift, and the joint transforms the functions of q alone start from.
struct ConstraintJoints {
  Kinematics kin;                     // XT, XJ, S, the bodies' own inertias (v = c = 0)
  const CodeBuilder* host = nullptr;  // the helper's state, imported by the functions
  std::string text;                   // the body of constraint_joints(q, w)
};
/// The helper host constraint_joints(q, w): the joint transforms of every body
/// (`all`: the Delassus functions need the off-support inertias) or of the support.
ConstraintJoints emitConstraintJoints(Emit& e, bool all);
/// The functions' bodies; drift calls kinematics(q, v, w), whose state (kin) lives in `from`.
std::string emitConstraintPlacements(Emit& e, const ConstraintJoints& joints);
std::string emitConstraintJacobian(Emit& e, const ConstraintJoints& joints);
std::string emitConstraintDrift(Emit& e, const Kinematics& kin, const CodeBuilder* from);
/// Ends the open part and multiplies out[r * cols + c] (the host's values) by
/// row r's activity factor (and, `columnsToo`, by column c's: G's rows and
/// columns): the rows of an inactive constraint become exact zeros.
void scheduleOutput(Emit& e, std::vector<Expr>& out, int cols, bool columnsToo);
/// Ends the open part and copies `out` (the host's values) to the output array `name`.
void copyOutput(Emit& e, const std::string& name, const std::vector<Expr>& out);

// ---- pass_constraint_wrenches.cpp: constraint_wrenches, each constraint's
// wrench on the robot in world axes from lambda (-R_C lambda).
std::string emitConstraintWrenches(Emit& e, const ConstraintJoints& joints);

// ---- pass_delassus.cpp: delassus (G = J M^-1 J^T) and, with `inverse`,
// delassus_inverse ((G + I/mu)^-1 by Woodbury on the penalised recursion).
std::string emitDelassus(Emit& e, const ConstraintJoints& joints, bool inverse);

// ---- pass_inverse_dynamics_derivatives.cpp: d tau / dq and d tau / dv of
// tau = RNEA(q, v, qdd) + J^T lambda at fixed qdd, lambda (in the world frame:
// docs/derivatives.md sections 2b and 5), from its copy of the state after kinematics.
/// One entry of a tangent as a later function reads it: a generation-time
/// constant, or the workspace member it was stored to.
struct TangentSlot {
  Expr value;
  std::string name;  // empty: `value` is the constant
};
using TangentCol = std::array<TangentSlot, 6>;
/// Which entries of a matrix can be nonzero: per row, its [lo, hi) column
/// ranges (the entries the emitter printed). The sparse products of
/// assemble.cpp (sparse_left_product_add, sparse_transposed_product) read only these.
using RowSpans = std::vector<std::vector<std::pair<int, int>>>;
/// The ranges of `rows` rows from the (row, column) entries that can be nonzero.
RowSpans rowSpans(int rows, const std::set<std::pair<int, int>>& entries);
/// Prints the tables the sparse products read, `<name>_start[rows + 1]` and
/// `<name>_span[2 ranges]`, as static constants of the function being written.
void printSpans(CodeBuilder& cb, const std::string& name, const RowSpans& spans);
/// The (column, row) entries of (row, column) entries: the pattern of the transpose.
std::set<std::pair<int, int>> transpose(const std::set<std::pair<int, int>>& entries);
/// The number of entries the ranges cover.
long entries(const RowSpans& spans);
/// Where copyBlock writes: rows `ld` apart (0: `cols`), from `offset`, negated or not.
struct CopyTo {
  int ld = 0;
  int offset = 0;
  bool negate = false;
};
/// dst[i cols + j] = src[i ld + offset + j], or src[j ld + offset + i] (`transposed`),
/// for i < rows, j < cols (dst's rows and start as `to` says): a loop over the rows
/// around one over the columns (the copy by one flat index, i = k / cols and
/// j = k % cols worked out per entry, took some 15 instructions an entry;
/// docs/benchmarks.md).
void copyBlock(CodeBuilder& cb, const std::vector<std::string>& names, const std::string& dst, const std::string& src,
               int rows, int cols, int ld, int offset, bool transposed, const CopyTo& to = {});
/// The arithmetic of sparse_left_product_add<n, m, p> and of
/// sparse_transposed_product<n, m, p> over the left factor's spans.
Ops sparseLeftProductOps(const RowSpans& a, int p);

/// What the tangent sweep hands to the functions that call it: where it left
/// each dof's world-frame vectors (the joint axis s, u, c, w: the columns of the
/// per-dof arrays, or the constants they fold to) and each body's placement and
/// velocity in world axes, from which constrained_dynamics_derivatives forms the
/// constraint rows; and d tau / dq's and d tau / dv's nonzero pattern (the
/// tree's: a joint's torque moves with its ancestors, itself and its subtree;
/// less a free flyer's translation columns of d tau / dq).
struct BodyTangents {
  std::vector<std::array<TangentCol, 4>> dof;  // per dof: s, u, c, w
  struct Body {
    TangentCol ov;                   // velocity in world axes
    std::array<TangentSlot, 9> R;    // world rotation (row-major)
    std::array<TangentSlot, 3> p;    // world position
  };
  std::vector<Body> body;
  std::set<std::pair<int, int>> dtauDq, dtauDv;  // (row, column) entries that can be nonzero
};
/// x as slots: each constant kept as it is, each other entry stored to
/// member(k) (`store`; false: already stored there, only named).
std::vector<TangentSlot> slotsOf(Emit& e, const std::vector<Expr>& x, const std::function<std::string(int)>& member,
                                 bool store = true);
/// A slot's value: its constant, or a read of its member.
Expr load(CodeBuilder& cb, const TangentSlot& s);
std::vector<Expr> load(CodeBuilder& cb, const std::vector<TangentSlot>& s);
V6 load(CodeBuilder& cb, const TangentCol& s);
/// The sweep's body, `tangent_sweep(q, v, qdd, lambda, w, dtau_dq, dtau_dv)`, which
/// reads the kinematics state in the workspace (joint transforms, v, c):
/// inverse_dynamics_derivatives is kinematics(q, v, w) and this; the derivative
/// functions that have just run a solver or RNEA on the same (q, v) call it
/// without a second kinematics pass. With `keep`, dtau's pattern and the
/// slots above are returned.
std::string emitInverseDynamicsDerivatives(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics,
                                           BodyTangents* keep = nullptr);
/// forward_dynamics_derivatives: calls nonlinear_effects, mass_matrix_inverse
/// and inverse_dynamics_derivatives (held with it) and the products with M^-1
/// (dense_product<n, m, p>, and sparse_transposed_product over dtau's pattern
/// in `t`, printed by assemble.cpp). denseProductOps: their arithmetic.
std::string emitForwardDynamicsDerivatives(Emit& e, const BodyTangents& t);
/// dqdd_dq = -M^-1 dtau_dq and dqdd_dv = -M^-1 dtau_dv (the callers' outputs)
/// over dtau's pattern in `t`: M^-1 in `minv`, the tangents in `dq`, `dv`,
/// the transposed product in the nv x nv member `scratch`; `names`: the host's parameters.
void minvTimesDtau(Emit& e, const BodyTangents& t, const std::string& minv, const std::string& dq,
                   const std::string& dv, const std::string& scratch, const std::vector<std::string>& names);
Ops denseProductOps(int n, int m, int p);

// ---- pass_constrained_dynamics_derivatives.cpp: constrained_dynamics_derivatives
// (docs/derivatives.md section 3): prox_pv, the sweep at its solution, the
// constraint rows' derivatives (from the sweep's world-frame vectors in `t`, a
// loop per run of path columns of one shape), the dense algebra of the
// implicit function theorem (fixed-bound loops printed by assemble.cpp).
std::string emitConstrainedDynamicsDerivatives(Emit& e, const BodyTangents& t);
/// What assemble.cpp's dense helpers compute, for the banner.
Ops denseProductAddOps(int n, int m, int p);
Ops denseCholeskyOps(int n);
Ops proximalInverseOps(int n);
Ops proximalPowerOps(int n);
Ops se3RightJacobianInverseOps();

}  // namespace proxgen::emit

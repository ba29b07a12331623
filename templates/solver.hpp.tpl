R"proxgen({banner}//
// Constrained forward dynamics of this robot and this constraint layout by
// constrainedABA and proxPV (the seed paper's recursions), as straight-line
// code. Conventions: q = [{q_convention}], v and qdd in the joint order below,
// lambda rows in layout order; the constraint force on the robot is -J^T lambda,
// so M qdd + h = tau - J^T lambda. Needs only "proxgen/runtime.hpp".
//
// Joint order (slots in q | v):
{joint_table}//
// Constraint rows (layout order):
{constraint_table}
#pragma once

namespace {name} {{

using Scalar = {scalar};
inline constexpr int nq = {nq}, nv = {nv}, nc = {nc};  // configuration, velocity, constraint rows

struct Settings {{
  Scalar mu = {mu};  // augmented-Lagrangian penalty (large = stiff)
  int iterations = {iterations};  // multiplier updates K (0: the unconstrained motion)
}};

// Everything one solve writes ({workspace_bytes} bytes): per-body quantities named
// <quantity>_<link>. Caller-owned, so the solvers are re-entrant and allocate nothing.
struct Workspace {{
{members}}};

// q[nq], v[nv], tau[nv] in; qdd[nv], lambda[nc] out (none of them inside w).
// K = s.iterations multiplier updates from lambda = 0; both algorithms give the
// same iterates up to round-off.
void constrained_aba(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,
                     Scalar* qdd, Scalar* lambda) noexcept;
void prox_pv(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,
             Scalar* qdd, Scalar* lambda) noexcept;
{constraint_declarations}
}}  // namespace {name}
)proxgen"

R"proxgen({banner}//
// Constrained forward dynamics of this robot and this constraint layout by
// constrainedABA and proxPV (the seed paper's recursions), as straight-line
// code. Conventions: q = [{q_convention}], v and qdd in the joint order below,
// lambda rows in layout order. Needs only "proxgen/runtime.hpp".
//
// Joint order (slots in q | v):
{joint_table}//
// Constraint rows (layout order):
{constraint_table}
#pragma once

namespace {name} {{

using Scalar = {scalar};
inline constexpr int nq = {nq}, nv = {nv}, nc = {nc};  // configuration, velocity, constraint rows
inline constexpr int ncons = {ncons};  // constraints in the layout (each 3 or 6 rows)

// The proxgen that printed this file; the source checks it against the
// runtime's proxgen_rt::version_major/minor when it is compiled.
inline constexpr const char* proxgen_version = "{version}";
inline constexpr int version_major = {version_major}, version_minor = {version_minor};

// Names and slots, so callers never count by hand. Joints in the order above
// (joint_idx_q[k], joint_idx_v[k]: the first slot of joint k in q and v);
// constraints in layout order (rows constraint_row[k] ..
// constraint_row[k] + constraint_rows[k] - 1 of lambda). The strings are the
// URDF's and the layout's names byte for byte; the identifiers in joint:: and
// constraint:: are those names sanitised (docs/design.md, "Names in the
// generated files"), the same ones the workspace members use.{empty_arrays}
inline constexpr const char* joint_names[] = {{{joint_names}}};
inline constexpr int joint_idx_q[] = {{{joint_idx_q}}};
inline constexpr int joint_idx_v[] = {{{joint_idx_v}}};
inline constexpr const char* constraint_names[] = {{{constraint_names}}};
inline constexpr int constraint_row[] = {{{constraint_row}}};
inline constexpr int constraint_rows[] = {{{constraint_rows}}};
namespace joint {{  // position in the joint list (joint_names)
{joint_ids}}}  // namespace joint
namespace constraint {{  // position in the layout (constraint_names)
{constraint_ids}}}  // namespace constraint

// Every constraint active: the default schedule of the functions taking one.
inline constexpr bool all_active[{active_size}] = {{{active_init}}};

// Set the fields by name (later versions may add fields).
struct Settings {{
  Scalar mu = {mu};  // augmented-Lagrangian penalty (large = stiff)
  int iterations = {iterations};  // multiplier updates K (0: the motion under the forces of lambda0)
  // Run-time contact schedule: active[k] for constraint k of the layout
  // (constraint::<name>). An inactive constraint exerts no force: its
  // multipliers are 0 and the answer is that of the solver generated without it
  // (to round-off; docs/algorithms.md section 4.4). Change it between calls freely.{active_note}
  bool active[{active_size}] = {{{active_init}}};
  // Warm start: nc multipliers (layout order; e.g. the previous control step's
  // lambda), or null for lambda = 0. The K updates start from lambda0 instead
  // of 0. It is read before lambda is written: it may be the lambda output.
  const Scalar* lambda0 = nullptr;
}};

// Everything one solve writes ({workspace_bytes} bytes): per-body quantities named
// <quantity>_<link>. Caller-owned, so the solvers are re-entrant and allocate nothing.
struct Workspace {{
{members}}};

{declarations}
}}  // namespace {name}
)proxgen"

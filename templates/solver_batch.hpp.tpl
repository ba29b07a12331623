R"proxgen({banner}//
// The batched solvers of {name}.hpp: {width} states per call, one in each lane
// of a vector register (proxgen_rt::lanes, "proxgen/lanes.hpp"; docs/batch.md).
// Each lane's answer is the scalar solver's on that state: the same
// operations in the same order (docs/batch.md, "Lane by lane").
#pragma once

#include "{name}.hpp"
#include "proxgen/lanes.hpp"

namespace {name} {{

inline constexpr int batch_width = {width};  // states per call of the _batch functions
using BatchScalar = proxgen_rt::lanes<Scalar, batch_width>;  // one Scalar of each of the states
{out_size}
// Everything one batched solve writes: the Workspace over lanes (batch_width
// times its size) and the states in lanes. Caller-owned, fixed size: the
// solvers allocate nothing; one per thread.
struct BatchWorkspace {{
  struct Lanes {{
{members}  }} w;
  BatchScalar q[nq], v[nv], tau[nv], qdd[nv];  // the states in lanes
  BatchScalar lambda[{rows}], lambda0[{rows}];{rows_note}
{out_members}}};

// Lane-interleaved: element i of state l at [i * batch_width + l] (q holds
// nq * batch_width values; v, tau and qdd nv * batch_width; lambda nc *
// batch_width). The Settings are shared by the states (mu, iterations,
// active), except the warm start: s.lambda0, when not null, holds nc *
// batch_width multipliers, lane-interleaved as lambda. What the scalar
// functions say of q, v, tau, qdd and lambda holds lane by lane.
void constrained_aba_batch(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                           Scalar* qdd, Scalar* lambda) noexcept;
void prox_pv_batch(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                   Scalar* qdd, Scalar* lambda) noexcept;

// Any number n of states (n <= 0: none) in the plain layout: state k's q at
// q + k * nq; v, tau and qdd at + k * nv; lambda (and s.lambda0, when not
// null) at + k * nc. Full batches of batch_width states through the kernels
// above, then the rest in one batch whose unused lanes repeat its first state
// (their answers are dropped). Re-entrant: one workspace per thread.
void constrained_aba_many(int n, const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s,
                          BatchWorkspace& w, Scalar* qdd, Scalar* lambda) noexcept;
void prox_pv_many(int n, const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                  Scalar* qdd, Scalar* lambda) noexcept;

// residual(w) of each lane of the last batched solve with w: batch_width
// values into r (after a _many call, those of its last batch).
void residual_batch(const BatchWorkspace& w, Scalar* r) noexcept;
{library}
}}  // namespace {name}
)proxgen"

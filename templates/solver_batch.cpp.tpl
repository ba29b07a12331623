R"proxgen({banner}
#include "{name}_batch.hpp"

#include "proxgen/lanes.hpp"

namespace {name} {{

// This file was printed for the runtime of the same version (runtime.hpp).
static_assert(proxgen_rt::version_major == version_major);
static_assert(proxgen_rt::version_minor == version_minor);

// {name}.cpp's functions over lanes: its text, with Scalar one value of each of
// the batch_width states, the Workspace over lanes, and the warm start in lanes.
namespace batch_lanes {{

using Scalar = BatchScalar;
using Workspace = BatchWorkspace::Lanes;
struct Settings : ::{name}::Settings {{
  const Scalar* lambda0 = nullptr;  // hides the base's: nc multipliers in lanes, or null
}};

namespace {{
{body}}}  // namespace batch_lanes

namespace {{

using Solve = void (*)(const BatchScalar*, const BatchScalar*, const BatchScalar*, const batch_lanes::Settings&,
                       BatchWorkspace::Lanes&, BatchScalar*, BatchScalar*) noexcept;

// The shared settings, and the warm start (already in w.lambda0) when there is one.
batch_lanes::Settings laneSettings(const Settings& s, const BatchWorkspace& w) noexcept {{
  batch_lanes::Settings ls;
  static_cast<Settings&>(ls) = s;
  ls.lambda0 = s.lambda0 ? w.lambda0 : nullptr;
  return ls;
}}

template <Solve solve>
void runBatch(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w, Scalar* qdd,
              Scalar* lambda) noexcept {{
  constexpr int W = batch_width;
  for (int i = 0; i < nq; ++i) w.q[i] = BatchScalar::load(q + i * W);
  for (int i = 0; i < nv; ++i) w.v[i] = BatchScalar::load(v + i * W);
  for (int i = 0; i < nv; ++i) w.tau[i] = BatchScalar::load(tau + i * W);
  for (int r = 0; r < nc && s.lambda0; ++r) w.lambda0[r] = BatchScalar::load(s.lambda0 + r * W);
  solve(w.q, w.v, w.tau, laneSettings(s, w), w.w, w.qdd, w.lambda);
  for (int i = 0; i < nv; ++i) w.qdd[i].store(qdd + i * W);
  for (int r = 0; r < nc; ++r) w.lambda[r].store(lambda + r * W);
}}

// n plain-layout states, batch_width at a time; the last batch's unused lanes
// hold its first state.
template <Solve solve>
void runMany(int n, const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
             Scalar* qdd, Scalar* lambda) noexcept {{
  constexpr int W = batch_width;
  for (int first = 0; first < n; first += W) {{
    const int used = n - first < W ? n - first : W;
    for (int l = 0; l < W; ++l) {{
      const std::size_t k = std::size_t(first + (l < used ? l : 0));
      for (int i = 0; i < nq; ++i) w.q[i].set(l, q[k * nq + std::size_t(i)]);
      for (int i = 0; i < nv; ++i) w.v[i].set(l, v[k * nv + std::size_t(i)]);
      for (int i = 0; i < nv; ++i) w.tau[i].set(l, tau[k * nv + std::size_t(i)]);
      for (int r = 0; r < nc && s.lambda0; ++r) w.lambda0[r].set(l, s.lambda0[k * nc + std::size_t(r)]);
    }}
    solve(w.q, w.v, w.tau, laneSettings(s, w), w.w, w.qdd, w.lambda);
    for (int l = 0; l < used; ++l) {{
      const std::size_t k = std::size_t(first + l);
      for (int i = 0; i < nv; ++i) qdd[k * nv + std::size_t(i)] = w.qdd[i][l];
      for (int r = 0; r < nc; ++r) lambda[k * nc + std::size_t(r)] = w.lambda[r][l];
    }}
  }}
}}

}}  // namespace

void constrained_aba_batch(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                           Scalar* qdd, Scalar* lambda) noexcept {{
  runBatch<batch_lanes::constrained_aba>(q, v, tau, s, w, qdd, lambda);
}}

void prox_pv_batch(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                   Scalar* qdd, Scalar* lambda) noexcept {{
  runBatch<batch_lanes::prox_pv>(q, v, tau, s, w, qdd, lambda);
}}

void constrained_aba_many(int n, const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s,
                          BatchWorkspace& w, Scalar* qdd, Scalar* lambda) noexcept {{
  runMany<batch_lanes::constrained_aba>(n, q, v, tau, s, w, qdd, lambda);
}}

void prox_pv_many(int n, const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, BatchWorkspace& w,
                  Scalar* qdd, Scalar* lambda) noexcept {{
  runMany<batch_lanes::prox_pv>(n, q, v, tau, s, w, qdd, lambda);
}}

void residual_batch(const BatchWorkspace& w, Scalar* r) noexcept {{
  batch_lanes::residual(w.w).store(r);
}}
{library}
}}  // namespace {name}
)proxgen"

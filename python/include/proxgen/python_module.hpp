// The body of a generated solver's Python module (NAME_python.cpp, from
// templates/python_module.cpp.tpl): binds NAME::prox_pv and
// NAME::constrained_aba, with the run-time schedule (active) and the warm start
// (lambda0), and every library function the solver was generated with
// (inverse_dynamics, mass_matrix, ...: bind* below), for one state (nq,) or
// many (N, nq), numpy in and out. Many states loop the scalar function with the
// GIL released; one state keeps the GIL (releasing it would cost more than the
// small solves take). Bad input: python_arrays.hpp.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <chrono>
#include <initializer_list>
#include <string>
#include <vector>

#include "proxgen/python_arrays.hpp"

namespace proxgen::python {

struct JointInfo {
  const char* name;
  const char* type;  // "revolute", "prismatic", "free_flyer"
  int idx_q, nq, idx_v, nv;
};

struct ConstraintInfo {
  const char* name;
  const char* type;  // "6d", "3d"
  int row, rows;
};

struct ModuleInfo {
  const char* name;
  const char* scalar;
  std::vector<JointInfo> joints;
  std::vector<ConstraintInfo> constraints;
  int quaternionAt = -1;  // q index of the free-flyer quaternion, or -1
};

// Solver: the generated namespace seen through a struct (Scalar, Settings,
// Workspace, nq, nv, nc, and the two solvers as static functions).
/// active: None -> every constraint active, else one truth value per
/// constraint of the layout (a sequence or array of bools or 0/1; the order of
/// constraint_names), written into out[0..ncons).
inline void readActive(py::handle active, std::size_t ncons, bool* out) {
  for (std::size_t k = 0; k < ncons; ++k) out[k] = true;
  if (active.is_none()) return;
  py::array a = py::array::ensure(active);
  if (!a || a.ndim() != 1 || std::size_t(a.shape(0)) != ncons)
    throw py::value_error("active: expected one flag per constraint, shape (" + std::to_string(ncons) + ",), got " +
                          (a ? shapeText(a) : std::string(py::str(py::type::handle_of(active).attr("__name__")))));
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u')
    throw py::type_error("active: expected bools or 0/1, got dtype " + std::string(py::str(a.dtype())));
  auto flags = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
  for (std::size_t k = 0; k < ncons; ++k) {
    const long long x = flags.data()[k];
    if (x != 0 && x != 1) throw py::value_error("active[" + std::to_string(k) + "]: expected a bool or 0/1, got " + std::to_string(x));
    out[k] = x == 1;
  }
}

// Solver: the generated namespace seen through a struct (Scalar, Settings,
// Workspace, nq, nv, nc, and the two solvers as static functions).
template <class Solver, void (*Solve)(const typename Solver::Scalar*, const typename Solver::Scalar*,
                                      const typename Solver::Scalar*, const typename Solver::Settings&,
                                      typename Solver::Workspace&, typename Solver::Scalar*,
                                      typename Solver::Scalar*) noexcept>
py::tuple solveStates(const ModuleInfo& info, py::handle q, py::handle v, py::handle tau, py::handle mu,
                      py::handle iterations, py::handle active, py::handle lambda0) {
  using Scalar = typename Solver::Scalar;
  constexpr int nq = Solver::nq, nv = Solver::nv, nc = Solver::nc;
  const typename Solver::Settings defaults;
  typename Solver::Settings s;
  s.mu = Scalar(readMu(mu, double(defaults.mu)));
  s.iterations = readIterations(iterations, defaults.iterations);
  readActive(active, info.constraints.size(), s.active);
  States<Scalar> in = readStates<Scalar>(q, v, tau, nq, nv);
  // lambda0: the warm start, one row of nc per state, or None for lambda = 0.
  py::array_t<Scalar> lambda0Array;
  const Scalar* lambda0In = nullptr;
  if (!lambda0.is_none()) {
    lambda0Array = asArray<Scalar>(lambda0, "lambda0");
    lambda0In = checkShape(lambda0Array, nc, "lambda0", in.batch, "nc");
    checkFinite(lambda0In, in.count() * nc, nc, "lambda0");
  }
  py::array_t<Scalar> qdd = newOutput<Scalar>(in.batch, nv);
  py::array_t<Scalar> lambda = newOutput<Scalar>(in.batch, nc);
  Scalar* qddOut = qdd.mutable_data();
  Scalar* lambdaOut = lambda.mutable_data();
  // One workspace per thread: the solvers are re-entrant given their own.
  thread_local typename Solver::Workspace w;
  Scalar qn[nq];
  if (in.batch == 0) {
    normalisedConfiguration(in.q, nq, info.quaternionAt, 0, false, qn);
    s.lambda0 = lambda0In;
    Solve(qn, in.v, in.tau, s, w, qddOut, lambdaOut);
  } else {
    // Every state is checked before the GIL goes: errors are raised with it held.
    for (py::ssize_t k = 0; k < in.batch; ++k) normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < in.batch; ++k) {
      normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
      s.lambda0 = lambda0In ? lambda0In + k * nc : nullptr;
      Solve(qn, in.v + k * nv, in.tau + k * nv, s, w, qddOut + k * nv, lambdaOut + k * nc);
    }
  }
  return py::make_tuple(std::move(qdd), std::move(lambda));
}

// Seconds per call of the C++ solver alone, looped `repeats` times on one
// checked state: what bench/python_overhead.py compares the module's call with.
template <class Solver, void (*Solve)(const typename Solver::Scalar*, const typename Solver::Scalar*,
                                      const typename Solver::Scalar*, const typename Solver::Settings&,
                                      typename Solver::Workspace&, typename Solver::Scalar*,
                                      typename Solver::Scalar*) noexcept>
double cppSecondsPerCall(const ModuleInfo& info, py::handle q, py::handle v, py::handle tau, long repeats) {
  using Scalar = typename Solver::Scalar;
  if (repeats < 1) throw py::value_error("repeats: expected an integer >= 1");
  States<Scalar> in = readStates<Scalar>(q, v, tau, Solver::nq, Solver::nv);
  if (in.batch != 0) throw py::value_error("q: expected one state");
  Scalar qn[Solver::nq], qdd[Solver::nv], lambda[Solver::nc + 1];
  normalisedConfiguration(in.q, Solver::nq, info.quaternionAt, 0, false, qn);
  const typename Solver::Settings s;
  thread_local typename Solver::Workspace w;
  py::gil_scoped_release release;
  const auto start = std::chrono::steady_clock::now();
  for (long k = 0; k < repeats; ++k) {
    Solve(qn, in.v, in.tau, s, w, qdd, lambda);
    // Keep the compiler from hoisting the pure call out of the loop.
    asm volatile("" : : "r"(qdd), "r"(lambda) : "memory");
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / double(repeats);
}

// ---- The library functions (docs/dynamics.md), when the solver holds them ----

/// The array arguments of one call of a library function, q first (it sets
/// the batch: one state or N), each `width` numbers per state, finite.
template <class Solver>
struct Inputs {
  using Scalar = typename Solver::Scalar;
  py::ssize_t batch = -1;
  std::array<py::array_t<Scalar>, 4> keep;  // copies made, alive for the call
  int count = 0;
  const Scalar* q;
  explicit Inputs(py::handle qObj) : q(add(qObj, "q", Solver::nq, "nq")) {}
  const Scalar* add(py::handle obj, const char* arg, py::ssize_t width, const char* sizeName) {
    py::array_t<Scalar>& a = keep.at(std::size_t(count++));  // (a binding with a fifth array is a bug: throws)
    a = asArray<Scalar>(obj, arg);
    const Scalar* x = checkShape(a, width, arg, batch, sizeName);
    checkFinite(x, (batch == 0 ? 1 : batch) * width, width, arg);
    return x;
  }
};

/// N new arrays, output j of shape dims[j] (one state) or (batch, *dims[j]),
/// filled by call(k, qn, w, outs_k) for each state k with its normalised
/// configuration qn and outs_k[j] its block of output j: every quaternion is
/// checked first (errors are raised with the GIL held), then many states run
/// with the GIL released, one workspace per thread.
template <class Solver, std::size_t N, class Call>
std::array<py::array_t<typename Solver::Scalar>, N> eachStateOutputs(const ModuleInfo& info, const Inputs<Solver>& in,
                                                                     const std::array<std::vector<py::ssize_t>, N>& dims,
                                                                     Call call) {
  using Scalar = typename Solver::Scalar;
  constexpr int nq = Solver::nq;
  std::array<py::array_t<Scalar>, N> out;
  std::array<Scalar*, N> at{};
  std::array<py::ssize_t, N> block{};
  for (std::size_t j = 0; j < N; ++j) {
    std::vector<py::ssize_t> shape;
    if (in.batch != 0) shape.push_back(in.batch);
    block[j] = 1;
    for (py::ssize_t d : dims[j]) {
      shape.push_back(d);
      block[j] *= d;
    }
    out[j] = py::array_t<Scalar>(shape);
    at[j] = out[j].mutable_data();
  }
  thread_local typename Solver::Workspace w;
  Scalar qn[nq];
  if (in.batch == 0) {
    normalisedConfiguration(in.q, nq, info.quaternionAt, 0, false, qn);
    call(py::ssize_t(0), qn, w, at);
    return out;
  }
  for (py::ssize_t k = 0; k < in.batch; ++k) normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
  py::gil_scoped_release release;
  for (py::ssize_t k = 0; k < in.batch; ++k) {
    normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
    std::array<Scalar*, N> mine;
    for (std::size_t j = 0; j < N; ++j) mine[j] = at[j] + k * block[j];
    call(k, qn, w, mine);
  }
  return out;
}

/// One output: eachStateOutputs with call(k, qn, w, out_k).
template <class Solver, class Call>
py::array_t<typename Solver::Scalar> eachState(const ModuleInfo& info, const Inputs<Solver>& in,
                                               std::initializer_list<py::ssize_t> dims, Call call) {
  const std::array<std::vector<py::ssize_t>, 1> shape{std::vector<py::ssize_t>(dims)};
  return eachStateOutputs<Solver, 1>(info, in, shape, [&](py::ssize_t k, auto* qn, auto& w, auto& outs) {
    call(k, qn, w, outs[0]);
  })[0];
}

template <class Solver>
using Scalar_t = typename Solver::Scalar;
template <class Solver>
using Workspace_t = typename Solver::Workspace;
// The schedule's flags of one call (all true without `active`).
template <class Solver>
struct Flags {
  bool at[Solver::ncons > 0 ? Solver::ncons : 1] = {};
  Flags(py::handle active, const ModuleInfo& info) { readActive(active, info.constraints.size(), at); }
};

/// f(q) -> (rows, cols): mass_matrix, mass_matrix_inverse.
template <class Solver>
void bindMatrixOfQ(py::module_& m, const ModuleInfo& info, const char* name,
                   void (*fn)(const Scalar_t<Solver>*, Workspace_t<Solver>&, Scalar_t<Solver>*) noexcept, int rows,
                   int cols, const char* doc) {
  const ModuleInfo* p = &info;
  m.def(
      name,
      [p, fn, rows, cols](py::handle q) {
        const Inputs<Solver> in(q);
        return eachState<Solver>(*p, in, {rows, cols}, [&](py::ssize_t, auto* qn, auto& w, auto* o) { fn(qn, w, o); });
      },
      py::arg("q"), doc);
}

/// f(q, active=None) -> (rows, cols): constraint_jacobian, delassus.
template <class Solver>
void bindScheduledMatrixOfQ(py::module_& m, const ModuleInfo& info, const char* name,
                            void (*fn)(const Scalar_t<Solver>*, Workspace_t<Solver>&, Scalar_t<Solver>*,
                                       const bool*) noexcept,
                            int rows, int cols, const char* doc) {
  const ModuleInfo* p = &info;
  m.def(
      name,
      [p, fn, rows, cols](py::handle q, py::handle active) {
        const Flags<Solver> flags(active, *p);
        const Inputs<Solver> in(q);
        return eachState<Solver>(*p, in, {rows, cols},
                                 [&](py::ssize_t, auto* qn, auto& w, auto* o) { fn(qn, w, o, flags.at); });
      },
      py::arg("q"), py::arg("active") = py::none(), doc);
}

/// nonlinear_effects(q, v) -> (nv,).
template <class Solver>
void bindNonlinearEffects(py::module_& m, const ModuleInfo& info,
                          void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, Workspace_t<Solver>&,
                                     Scalar_t<Solver>*) noexcept) {
  constexpr int nv = Solver::nv;
  const ModuleInfo* p = &info;
  m.def(
      "nonlinear_effects",
      [p, fn](py::handle q, py::handle v) {
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        return eachState<Solver>(*p, in, {nv}, [&](py::ssize_t k, auto* qn, auto& w, auto* o) { fn(qn, vin + k * nv, w, o); });
      },
      py::arg("q"), py::arg("v"), "(q, v) -> h (nv,) or (N, nv): Coriolis, centrifugal and gravity torques.");
}

/// constraint_drift(q, v, active=None) -> (nc,).
template <class Solver>
void bindConstraintDrift(py::module_& m, const ModuleInfo& info,
                         void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, Workspace_t<Solver>&,
                                    Scalar_t<Solver>*, const bool*) noexcept) {
  constexpr int nv = Solver::nv, nc = Solver::nc;
  const ModuleInfo* p = &info;
  m.def(
      "constraint_drift",
      [p, fn](py::handle q, py::handle v, py::handle active) {
        const Flags<Solver> flags(active, *p);
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        return eachState<Solver>(*p, in, {nc},
                                 [&](py::ssize_t k, auto* qn, auto& w, auto* o) { fn(qn, vin + k * nv, w, o, flags.at); });
      },
      py::arg("q"), py::arg("v"), py::arg("active") = py::none(),
      "(q, v, active=None) -> gamma (nc,) or (N, nc): J qdd + gamma is the constraint rows' acceleration.");
}

/// inverse_dynamics(q, v, qdd, lam=None, active=None) -> tau (nv,).
template <class Solver>
void bindInverseDynamics(py::module_& m, const ModuleInfo& info,
                         void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, const Scalar_t<Solver>*,
                                    const Scalar_t<Solver>*, Workspace_t<Solver>&, Scalar_t<Solver>*,
                                    const bool*) noexcept) {
  constexpr int nv = Solver::nv, nc = Solver::nc;
  const ModuleInfo* p = &info;
  m.def(
      "inverse_dynamics",
      [p, fn](py::handle q, py::handle v, py::handle qdd, py::handle lam, py::handle active) {
        const Flags<Solver> flags(active, *p);
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        const auto* ain = in.add(qdd, "qdd", nv, "nv");
        const auto* lin = lam.is_none() ? nullptr : in.add(lam, "lam", nc, "nc");
        return eachState<Solver>(*p, in, {nv}, [&](py::ssize_t k, auto* qn, auto& w, auto* o) {
          fn(qn, vin + k * nv, ain + k * nv, lin ? lin + k * nc : nullptr, w, o, flags.at);
        });
      },
      py::arg("q"), py::arg("v"), py::arg("qdd"), py::arg("lam") = py::none(), py::arg("active") = py::none(),
      "(q, v, qdd, lam=None, active=None) -> tau (nv,) or (N, nv): M qdd + h + J^T lam (lam None: no\n"
      "constraint forces; the rows of an inactive constraint are not read).");
}

/// constraint_placements(q) -> (ncons, 4, 4): each constraint frame's world
/// placement [R p; 0 0 0 1], as the package's Robot.constraint_placements.
template <class Solver>
void bindConstraintPlacements(py::module_& m, const ModuleInfo& info,
                              void (*fn)(const Scalar_t<Solver>*, Workspace_t<Solver>&, Scalar_t<Solver>*) noexcept) {
  using Scalar = Scalar_t<Solver>;
  constexpr int ncons = Solver::ncons;
  const ModuleInfo* p = &info;
  m.def(
      "constraint_placements",
      [p, fn](py::handle q) {
        const Inputs<Solver> in(q);
        return eachState<Solver>(*p, in, {ncons, 4, 4}, [&](py::ssize_t, auto* qn, auto& w, Scalar* o) {
          Scalar X[ncons > 0 ? 12 * ncons : 1];
          fn(qn, w, X);
          for (int c = 0; c < ncons; ++c) {
            Scalar* T = o + c * 16;
            for (int i = 0; i < 3; ++i) {
              for (int j = 0; j < 3; ++j) T[4 * i + j] = X[12 * c + 3 * i + j];
              T[4 * i + 3] = X[12 * c + 9 + i];
              T[12 + i] = Scalar(0);
            }
            T[15] = Scalar(1);
          }
        });
      },
      py::arg("q"), "(q) -> (ncons, 4, 4) or (N, ncons, 4, 4): each constraint frame's world placement [R p; 0 0 0 1].");
}

/// delassus_inverse(q, mu=None, active=None) -> (G + I/mu)^-1 (nc, nc).
template <class Solver>
void bindDelassusInverse(py::module_& m, const ModuleInfo& info,
                         void (*fn)(const Scalar_t<Solver>*, const typename Solver::Settings&, Workspace_t<Solver>&,
                                    Scalar_t<Solver>*) noexcept) {
  constexpr int nc = Solver::nc;
  const ModuleInfo* p = &info;
  m.def(
      "delassus_inverse",
      [p, fn](py::handle q, py::handle mu, py::handle active) {
        const typename Solver::Settings defaults;
        typename Solver::Settings s;
        s.mu = Scalar_t<Solver>(readMu(mu, double(defaults.mu)));
        readActive(active, p->constraints.size(), s.active);
        const Inputs<Solver> in(q);
        return eachState<Solver>(*p, in, {nc, nc}, [&](py::ssize_t, auto* qn, auto& w, auto* o) { fn(qn, s, w, o); });
      },
      py::arg("q"), py::arg("mu") = py::none(), py::arg("active") = py::none(),
      "(q, mu=None, active=None) -> (G + I/mu)^-1 (nc, nc) or (N, nc, nc) (mu: the layout's by default;\n"
      "an inactive constraint's rows and columns are 0).");
}

/// constraint_wrenches(q, lam) -> (ncons, 6): each constraint's wrench on the
/// robot in world axes, force then torque about the frame's origin.
template <class Solver>
void bindConstraintWrenches(py::module_& m, const ModuleInfo& info,
                            void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, Workspace_t<Solver>&,
                                       Scalar_t<Solver>*) noexcept) {
  constexpr int nc = Solver::nc, ncons = Solver::ncons;
  const ModuleInfo* p = &info;
  m.def(
      "constraint_wrenches",
      [p, fn](py::handle q, py::handle lam) {
        Inputs<Solver> in(q);
        const auto* lin = in.add(lam, "lam", nc, "nc");
        return eachState<Solver>(*p, in, {ncons, 6},
                                 [&](py::ssize_t k, auto* qn, auto& w, auto* o) { fn(qn, lin + k * nc, w, o); });
      },
      py::arg("q"), py::arg("lam"),
      "(q, lam) -> (ncons, 6) or (N, ncons, 6): each constraint's wrench on the robot in world axes\n"
      "(force, then torque about the frame's origin); the constraint force on the robot is -J^T lam.");
}

/// inverse_dynamics_derivatives(q, v, qdd, lam=None) -> (dtau_dq, dtau_dv), (nv, nv) each.
template <class Solver>
void bindInverseDynamicsDerivatives(py::module_& m, const ModuleInfo& info,
                                    void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, const Scalar_t<Solver>*,
                                               const Scalar_t<Solver>*, Workspace_t<Solver>&, Scalar_t<Solver>*,
                                               Scalar_t<Solver>*) noexcept) {
  constexpr int nv = Solver::nv, nc = Solver::nc;
  const ModuleInfo* p = &info;
  m.def(
      "inverse_dynamics_derivatives",
      [p, fn](py::handle q, py::handle v, py::handle qdd, py::handle lam) {
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        const auto* ain = in.add(qdd, "qdd", nv, "nv");
        const auto* lin = lam.is_none() ? nullptr : in.add(lam, "lam", nc, "nc");
        const std::array<std::vector<py::ssize_t>, 2> dims{std::vector<py::ssize_t>{nv, nv}, std::vector<py::ssize_t>{nv, nv}};
        auto out = eachStateOutputs<Solver, 2>(*p, in, dims, [&](py::ssize_t k, auto* qn, auto& w, auto& o) {
          fn(qn, vin + k * nv, ain + k * nv, lin ? lin + k * nc : nullptr, w, o[0], o[1]);
        });
        return py::make_tuple(std::move(out[0]), std::move(out[1]));
      },
      py::arg("q"), py::arg("v"), py::arg("qdd"), py::arg("lam") = py::none(),
      "(q, v, qdd, lam=None) -> (dtau_dq, dtau_dv), (nv, nv) each or (N, nv, nv): the derivatives of\n"
      "inverse_dynamics at fixed qdd and lam; column k of d/dq is along q (+) t e_k (docs/derivatives.md).");
}

/// forward_dynamics_derivatives(q, v, tau) -> (qdd, dqdd_dq, dqdd_dv, dqdd_dtau).
template <class Solver>
void bindForwardDynamicsDerivatives(py::module_& m, const ModuleInfo& info,
                                    void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, const Scalar_t<Solver>*,
                                               Workspace_t<Solver>&, Scalar_t<Solver>*, Scalar_t<Solver>*,
                                               Scalar_t<Solver>*, Scalar_t<Solver>*) noexcept) {
  constexpr int nv = Solver::nv;
  const ModuleInfo* p = &info;
  m.def(
      "forward_dynamics_derivatives",
      [p, fn](py::handle q, py::handle v, py::handle tau) {
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        const auto* tin = in.add(tau, "tau", nv, "nv");
        const std::vector<py::ssize_t> square{nv, nv};
        const std::array<std::vector<py::ssize_t>, 4> dims{std::vector<py::ssize_t>{nv}, square, square, square};
        auto out = eachStateOutputs<Solver, 4>(*p, in, dims, [&](py::ssize_t k, auto* qn, auto& w, auto& o) {
          fn(qn, vin + k * nv, tin + k * nv, w, o[0], o[1], o[2], o[3]);
        });
        return py::make_tuple(std::move(out[0]), std::move(out[1]), std::move(out[2]), std::move(out[3]));
      },
      py::arg("q"), py::arg("v"), py::arg("tau"),
      "(q, v, tau) -> (qdd, dqdd_dq, dqdd_dv, dqdd_dtau) of the free motion (no constraint forces),\n"
      "(nv,) and (nv, nv), or with a leading N; column k of d/dq is along q (+) t e_k (docs/derivatives.md).");
}

/// constrained_dynamics_derivatives(q, v, tau, mu=None, iterations=None, active=None)
/// -> (qdd, lam, dqdd_dq, dqdd_dv, dqdd_dtau, dlam_dq, dlam_dv, dlam_dtau).
template <class Solver>
void bindConstrainedDynamicsDerivatives(
    py::module_& m, const ModuleInfo& info,
    void (*fn)(const Scalar_t<Solver>*, const Scalar_t<Solver>*, const Scalar_t<Solver>*,
               const typename Solver::Settings&, Workspace_t<Solver>&, Scalar_t<Solver>*, Scalar_t<Solver>*,
               Scalar_t<Solver>*, Scalar_t<Solver>*, Scalar_t<Solver>*, Scalar_t<Solver>*, Scalar_t<Solver>*,
               Scalar_t<Solver>*) noexcept) {
  constexpr int nv = Solver::nv, nc = Solver::nc;
  const ModuleInfo* p = &info;
  m.def(
      "constrained_dynamics_derivatives",
      [p, fn](py::handle q, py::handle v, py::handle tau, py::handle mu, py::handle iterations, py::handle active) {
        const typename Solver::Settings defaults;
        typename Solver::Settings s;
        s.mu = Scalar_t<Solver>(readMu(mu, double(defaults.mu)));
        s.iterations = readIterations(iterations, defaults.iterations);
        readActive(active, p->constraints.size(), s.active);
        Inputs<Solver> in(q);
        const auto* vin = in.add(v, "v", nv, "nv");
        const auto* tin = in.add(tau, "tau", nv, "nv");
        const std::vector<py::ssize_t> square{nv, nv}, rows{nc, nv};
        const std::array<std::vector<py::ssize_t>, 8> dims{std::vector<py::ssize_t>{nv}, std::vector<py::ssize_t>{nc},
                                                           square, square, square, rows, rows, rows};
        auto out = eachStateOutputs<Solver, 8>(*p, in, dims, [&](py::ssize_t k, auto* qn, auto& w, auto& o) {
          fn(qn, vin + k * nv, tin + k * nv, s, w, o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7]);
        });
        return py::make_tuple(std::move(out[0]), std::move(out[1]), std::move(out[2]), std::move(out[3]),
                              std::move(out[4]), std::move(out[5]), std::move(out[6]), std::move(out[7]));
      },
      py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("mu") = py::none(), py::arg("iterations") = py::none(),
      py::arg("active") = py::none(),
      "(q, v, tau, mu=None, iterations=None, active=None) -> (qdd, lam, dqdd_dq, dqdd_dv, dqdd_dtau,\n"
      "dlam_dq, dlam_dv, dlam_dtau): prox_pv's solution and its derivatives ((nv, nv) and (nc, nv),\n"
      "or with a leading N); column k of d/dq is along q (+) t e_k (docs/derivatives.md).");
}

template <class Solver>
void bindSolver(py::module_& m, const ModuleInfo& info) {
  m.attr("name") = info.name;
  m.attr("scalar") = info.scalar;
  m.attr("nq") = Solver::nq;
  m.attr("nv") = Solver::nv;
  m.attr("nc") = Solver::nc;
  const typename Solver::Settings defaults;
  m.attr("mu") = double(defaults.mu);
  m.attr("iterations") = defaults.iterations;
  py::list jointNames, constraintNames;
  py::dict joints, constraints;
  for (const JointInfo& j : info.joints) {
    jointNames.append(j.name);
    py::dict d;
    d["type"] = j.type;
    d["idx_q"] = j.idx_q;
    d["nq"] = j.nq;
    d["idx_v"] = j.idx_v;
    d["nv"] = j.nv;
    joints[j.name] = d;
  }
  for (const ConstraintInfo& c : info.constraints) {
    constraintNames.append(c.name);
    py::dict d;
    d["type"] = c.type;
    d["row"] = c.row;
    d["rows"] = c.rows;
    constraints[c.name] = d;
  }
  m.attr("joint_names") = py::tuple(jointNames);
  m.attr("constraint_names") = py::tuple(constraintNames);
  m.attr("joints") = joints;
  m.attr("constraints") = constraints;
  m.def(
      "_cpp_seconds_per_call",
      // The module itself, borrowed: it outlives its functions.
      [self = py::handle(m)](const std::string& function, py::handle q, py::handle v, py::handle tau, long repeats) {
        const std::string timer = "_cpp_seconds_per_call_" + function;
        if ((function != "prox_pv" && function != "constrained_aba") || !py::hasattr(self, timer.c_str()))
          throw py::value_error("function: expected a solver this module holds ('prox_pv' or 'constrained_aba'), got '" +
                                function + "'");
        return self.attr(timer.c_str())(q, v, tau, repeats).template cast<double>();
      },
      py::arg("function"), py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("repeats"),
      "Benchmark helper (bench/python_overhead.py): seconds per call of the C++ solver in a loop.");
}

/// One solver (prox_pv or constrained_aba) as `name`, with its timing helper.
template <class Solver, void (*Solve)(const typename Solver::Scalar*, const typename Solver::Scalar*,
                                      const typename Solver::Scalar*, const typename Solver::Settings&,
                                      typename Solver::Workspace&, typename Solver::Scalar*,
                                      typename Solver::Scalar*) noexcept>
void bindSolve(py::module_& m, const ModuleInfo& info, const char* name) {
  const char* doc =
      "(q, v, tau, mu=None, iterations=None, active=None, lambda0=None) -> (qdd, lam).\n"
      "q: (nq,) or (N, nq); v, tau: (nv,) or (N, nv); float or integer arrays (others copied once);\n"
      "mu, iterations default to the layout's; active: one flag per constraint (constraint_names\n"
      "order; an inactive one exerts no force, its lam rows are 0); lambda0: the warm start, (nc,)\n"
      "or (N, nc) as lam (None: from 0). Returns new arrays (nv,), (nc,) or (N, nv), (N, nc).\n"
      "Bad input raises ValueError or TypeError.";
  const ModuleInfo* p = &info;
  m.def(
      name,
      [p](py::handle q, py::handle v, py::handle tau, py::handle mu, py::handle k, py::handle active, py::handle lambda0) {
        return solveStates<Solver, Solve>(*p, q, v, tau, mu, k, active, lambda0);
      },
      py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("mu") = py::none(), py::arg("iterations") = py::none(),
      py::arg("active") = py::none(), py::arg("lambda0") = py::none(), doc);
  m.def(
      ("_cpp_seconds_per_call_" + std::string(name)).c_str(),
      [p](py::handle q, py::handle v, py::handle tau, long repeats) { return cppSecondsPerCall<Solver, Solve>(*p, q, v, tau, repeats); },
      py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("repeats"));
}

}  // namespace proxgen::python

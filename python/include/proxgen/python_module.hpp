// The body of a generated solver's Python module (NAME_python.cpp, from
// templates/python_module.cpp.tpl): binds NAME::prox_pv and
// NAME::constrained_aba for one state (nq,) or many (N, nq), numpy in and out.
// Many states loop the scalar solver with the GIL released (no batched kernels
// exist yet); one state keeps the GIL (releasing it would cost more than the
// small solves take). Bad input: python_arrays.hpp.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <chrono>
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
template <class Solver, void (*Solve)(const typename Solver::Scalar*, const typename Solver::Scalar*,
                                      const typename Solver::Scalar*, const typename Solver::Settings&,
                                      typename Solver::Workspace&, typename Solver::Scalar*,
                                      typename Solver::Scalar*) noexcept>
py::tuple solveStates(const ModuleInfo& info, py::handle q, py::handle v, py::handle tau, py::handle mu,
                      py::handle iterations) {
  using Scalar = typename Solver::Scalar;
  constexpr int nq = Solver::nq, nv = Solver::nv, nc = Solver::nc;
  const typename Solver::Settings defaults;
  typename Solver::Settings s;
  s.mu = Scalar(readMu(mu, double(defaults.mu)));
  s.iterations = readIterations(iterations, defaults.iterations);
  States<Scalar> in = readStates<Scalar>(q, v, tau, nq, nv);
  py::array_t<Scalar> qdd = newOutput<Scalar>(in.batch, nv);
  py::array_t<Scalar> lambda = newOutput<Scalar>(in.batch, nc);
  Scalar* qddOut = qdd.mutable_data();
  Scalar* lambdaOut = lambda.mutable_data();
  // One workspace per thread: the solvers are re-entrant given their own.
  thread_local typename Solver::Workspace w;
  Scalar qn[nq];
  if (in.batch == 0) {
    normalisedConfiguration(in.q, nq, info.quaternionAt, 0, false, qn);
    Solve(qn, in.v, in.tau, s, w, qddOut, lambdaOut);
  } else {
    // Every state is checked before the GIL goes: errors are raised with it held.
    for (py::ssize_t k = 0; k < in.batch; ++k) normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < in.batch; ++k) {
      normalisedConfiguration(in.q + k * nq, nq, info.quaternionAt, k, true, qn);
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
  const char* doc =
      "(q, v, tau, mu=None, iterations=None) -> (qdd, lam). q: (nq,) or (N, nq); v, tau: (nv,) or (N, nv);\n"
      "float or integer arrays (others copied once); mu, iterations default to the layout's.\n"
      "Returns new arrays (nv,), (nc,) or (N, nv), (N, nc). Bad input raises ValueError or TypeError.";
  const ModuleInfo* p = &info;
  m.def(
      "prox_pv",
      [p](py::handle q, py::handle v, py::handle tau, py::handle mu, py::handle k) {
        return solveStates<Solver, &Solver::prox_pv>(*p, q, v, tau, mu, k);
      },
      py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("mu") = py::none(), py::arg("iterations") = py::none(), doc);
  m.def(
      "constrained_aba",
      [p](py::handle q, py::handle v, py::handle tau, py::handle mu, py::handle k) {
        return solveStates<Solver, &Solver::constrained_aba>(*p, q, v, tau, mu, k);
      },
      py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("mu") = py::none(), py::arg("iterations") = py::none(), doc);
  m.def(
      "_cpp_seconds_per_call",
      [p](const std::string& function, py::handle q, py::handle v, py::handle tau, long repeats) {
        if (function == "prox_pv") return cppSecondsPerCall<Solver, &Solver::prox_pv>(*p, q, v, tau, repeats);
        if (function == "constrained_aba") return cppSecondsPerCall<Solver, &Solver::constrained_aba>(*p, q, v, tau, repeats);
        throw py::value_error("function: expected 'prox_pv' or 'constrained_aba'");
      },
      py::arg("function"), py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("repeats"),
      "Benchmark helper (bench/python_overhead.py): seconds per call of the C++ solver in a loop.");
}

}  // namespace proxgen::python

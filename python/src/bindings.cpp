// proxgen._proxgen: the host library seen from Python (wrapped by
// python/proxgen/__init__.py). Loads a System (URDF + layout file, layout text
// or none), runs the generic solvers exactly as `proxgen eval` does and the
// dynamics library as `proxgen eval --compute` does (one state per call), reads
// states keyed by joint name through the library's JSON reader (the same checks
// and messages as `eval --state`), and generates solvers in process.
// proxgen::Error becomes ValueError with its message.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/dense_reference.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea.hpp"
#include "emit/generate.hpp"
#include "emit/python_module.hpp"
#include "cases/cases.hpp"
#include "model/error.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"
#include "model/urdf.hpp"
#include "proxgen/python_arrays.hpp"

namespace py = pybind11;
using nlohmann::json;

namespace proxgen::python {
namespace {

// A System with the generic solvers' workspace (one per robot object; the
// generic solvers run with the GIL held, so one Data is enough).
struct Robot {
  System sys;
  Data data;
  int quaternionAt = -1;
  explicit Robot(System s) : sys(std::move(s)), data(sys) {
    for (int i = 1; i < sys.model.numBodies(); ++i)
      if (sys.model.bodies[i].joint.type == JointType::FreeFlyer) quaternionAt = sys.model.bodies[i].joint.idx_q + 3;
  }
};

enum class Algorithm { Caba, Pv, Ltl, Ltls, Dense };

Algorithm parseAlgorithm(py::handle a) {
  if (!py::isinstance<py::str>(a)) throw py::type_error("algorithm: expected a str (caba, pv, ltl, ltls or dense)");
  const std::string s = a.cast<std::string>();
  if (s == "caba") return Algorithm::Caba;
  if (s == "pv") return Algorithm::Pv;
  if (s == "ltl") return Algorithm::Ltl;
  if (s == "ltls") return Algorithm::Ltls;
  if (s == "dense") return Algorithm::Dense;
  throw py::value_error("algorithm: unknown algorithm " + quoted(s) + " (expected caba, pv, ltl, ltls or dense)");
}

// The dispatch of `proxgen eval` (generator/cli/eval.cpp).
void solveOne(Robot& r, Algorithm algorithm, const VecX& q, const VecX& v, const VecX& tau, double mu, int K, double* qdd,
              double* lambda) {
  const System& sys = r.sys;
  Data& d = r.data;
  if (algorithm == Algorithm::Dense) {
    VecX x, l;
    denseProx(assembleDense(sys, q, v, tau), mu, K, x, l);
    VecX::Map(qdd, sys.model.nv) = x;
    VecX::Map(lambda, sys.nc) = l;
    return;
  }
  switch (algorithm) {
    case Algorithm::Caba: constrainedAba(sys, d, q, v, tau, mu, K); break;
    case Algorithm::Pv: proxPv(sys, d, q, v, tau, mu, K); break;
    case Algorithm::Ltl: proxLtl(sys, d, q, v, tau, mu, K); break;
    case Algorithm::Ltls: proxLtls(sys, d, q, v, tau, mu, K); break;
    case Algorithm::Dense: break;
  }
  VecX::Map(qdd, sys.model.nv) = d.qdd;
  VecX::Map(lambda, sys.nc) = d.lambda;
}

py::tuple evalStates(Robot& r, py::handle q, py::handle v, py::handle tau, py::handle algorithm, py::handle iterations,
                     py::handle mu) {
  const Algorithm a = parseAlgorithm(algorithm);
  const double m = readMu(mu, r.sys.mu);
  const int K = readIterations(iterations, r.sys.iterations);
  const int nq = r.sys.model.nq, nv = r.sys.model.nv, nc = r.sys.nc;
  States<double> in = readStates<double>(q, v, tau, nq, nv);
  py::array_t<double> qdd = newOutput<double>(in.batch, nv), lambda = newOutput<double>(in.batch, nc);
  VecX qk(nq), vk(nv), tk(nv);
  for (py::ssize_t k = 0; k < in.count(); ++k) {
    normalisedConfiguration(in.q + k * nq, nq, r.quaternionAt, k, in.batch > 0, qk.data());
    vk = VecX::Map(in.v + k * nv, nv);
    tk = VecX::Map(in.tau + k * nv, nv);
    solveOne(r, a, qk, vk, tk, m, K, qdd.mutable_data() + k * nv, lambda.mutable_data() + k * nc);
  }
  return py::make_tuple(std::move(qdd), std::move(lambda));
}

// Python objects -> JSON for the library's state reader: dicts with str keys,
// lists and tuples, numpy arrays (through tolist), real numbers; bools and
// strings pass through so that the reader names them ("expected a number").
json toJson(py::handle x, const std::string& where) {
  if (x.is_none()) return nullptr;
  if (PyBool_Check(x.ptr())) return x.cast<bool>();
  if (py::isinstance<py::str>(x)) return x.cast<std::string>();
  if (py::isinstance<py::dict>(x)) {
    json out = json::object();
    for (const auto& item : x.cast<py::dict>()) {
      if (!py::isinstance<py::str>(item.first))
        throw py::type_error(where + ": keys must be str (joint names), got " +
                             std::string(py::str(py::type::handle_of(item.first).attr("__name__"))));
      const std::string key = item.first.cast<std::string>();
      out[key] = toJson(item.second, where + "." + key);
    }
    return out;
  }
  if (py::isinstance<py::array>(x)) return toJson(x.attr("tolist")(), where);
  if (py::isinstance<py::list>(x) || py::isinstance<py::tuple>(x)) {
    json out = json::array();
    for (py::handle e : x) out.push_back(toJson(e, where));
    return out;
  }
  if (PyLong_Check(x.ptr()) || PyFloat_Check(x.ptr()) || PyIndex_Check(x.ptr()) || py::hasattr(x, "__float__")) {
    const double d = PyFloat_AsDouble(x.ptr());
    if (d == -1.0 && PyErr_Occurred()) throw py::error_already_set();
    return d;  // NaN and inf stay, for the reader's "is not finite"
  }
  throw py::type_error(where + ": expected a dict, a list or a number, got " +
                       std::string(py::str(py::type::handle_of(x).attr("__name__"))));
}

py::array_t<double> toArray(const VecX& x) {
  py::array_t<double> a(x.size());
  VecX::Map(a.mutable_data(), x.size()) = x;
  return a;
}

// One state (q, v), checked and with the quaternion normalised as for eval.
void oneState(Robot& r, py::handle q, py::handle v, VecX& qk, VecX& vk) {
  const int nq = r.sys.model.nq, nv = r.sys.model.nv;
  States<double> in = readStates<double>(q, v, v, nq, nv);
  if (in.batch != 0) throw py::value_error("q: expected one state, shape (" + std::to_string(nq) + ",)");
  qk.resize(nq);
  normalisedConfiguration(in.q, nq, r.quaternionAt, 0, false, qk.data());
  vk = VecX::Map(in.v, nv);
}

// World placement (R, p) and frame velocity (6, [linear; angular] in C) of
// every constraint frame C, by name: what a simulation measures its drift with.
py::dict constraintFrames(Robot& r, py::handle q, py::handle v) {
  VecX qk, vk;
  oneState(r, q, v, qk, vk);
  forwardKinematics(r.sys, r.data, qk, vk);
  py::dict out;
  for (const Constraint& c : r.sys.constraints) {
    const SE3 M = framePlacement(r.data, c.body, c.placement);
    const Vec6 V = frameVelocity(r.data, c.body, c.placement);
    py::array_t<double> R({3, 3});
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R.mutable_at(i, j) = M.R(i, j);
    out[py::str(c.name)] = py::make_tuple(R, toArray(M.p), toArray(V));
  }
  return out;
}

// ||J qdd + gamma - aStar|| at (q, v): the "residual" of `proxgen eval`.
double residual(Robot& r, py::handle q, py::handle v, py::handle qdd) {
  VecX qk, vk;
  oneState(r, q, v, qk, vk);
  py::array_t<double> a = asArray<double>(qdd, "qdd");
  py::ssize_t batch = 0;
  const double* x = checkShape(a, r.sys.model.nv, "qdd", batch, "nv");
  checkFinite(x, r.sys.model.nv, r.sys.model.nv, "qdd");
  if (r.sys.nc == 0) return 0.0;
  constraintJacobian(r.sys, r.data, qk, vk);
  return (r.data.J * VecX::Map(x, r.sys.model.nv) + r.data.gamma - r.data.aStar).norm();
}

// --- the dynamics library (docs/dynamics.md), one state per call -------------

// One vector argument of shape (n,), real and finite, as a VecX.
VecX oneVector(py::handle x, int n, const char* arg, const char* sizeName) {
  py::array_t<double> a = asArray<double>(x, arg);
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(arg) + ": expected one state, shape (" + sizeName + ",) = (" + std::to_string(n) +
                          ",), got " + shapeText(a));
  checkFinite(a.data(), n, n, arg);
  return VecX::Map(a.data(), n);
}

// q checked and with the quaternion normalised, as for eval.
VecX oneConfiguration(const Robot& r, py::handle q) {
  const VecX raw = oneVector(q, r.sys.model.nq, "q", "nq");
  VecX out(raw.size());
  normalisedConfiguration(raw.data(), raw.size(), r.quaternionAt, 0, false, out.data());
  return out;
}

// Inputs are finite, yet a product can overflow: as `eval --compute`, no
// non-finite result comes back.
void requireFiniteResult(const double* x, Eigen::Index n, const char* what) {
  for (Eigen::Index k = 0; k < n; ++k)
    if (!std::isfinite(x[k])) throw py::value_error(std::string(what) + ": is not finite at this state (an intermediate overflowed)");
}

py::array_t<double> vectorOut(const VecX& x, const char* what) {
  requireFiniteResult(x.data(), x.size(), what);
  return toArray(x);
}

// A new C-ordered (rows, cols) array from an Eigen (column-major) matrix.
py::array_t<double> matrixOut(const MatX& A, const char* what) {
  requireFiniteResult(A.data(), A.size(), what);
  py::array_t<double> a({A.rows(), A.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(a.mutable_data(), A.rows(), A.cols()) = A;
  return a;
}

py::array_t<double> inverseDynamicsOf(Robot& r, py::handle q, py::handle v, py::handle qdd, py::handle lam) {
  const int nv = r.sys.model.nv;
  const VecX qk = oneConfiguration(r, q), vk = oneVector(v, nv, "v", "nv"), ak = oneVector(qdd, nv, "qdd", "nv");
  VecX l;
  if (!lam.is_none()) l = oneVector(lam, r.sys.nc, "lam", "nc");
  return vectorOut(inverseDynamics(r.sys, r.data, qk, vk, ak, lam.is_none() ? nullptr : &l), "inverse_dynamics");
}

py::array_t<double> nonlinearEffectsOf(Robot& r, py::handle q, py::handle v) {
  const VecX qk = oneConfiguration(r, q), vk = oneVector(v, r.sys.model.nv, "v", "nv");
  return vectorOut(nonLinearEffects(r.sys, r.data, qk, vk), "nonlinear_effects");
}

// (nconstraints, 4, 4): each constraint frame's world placement as a
// homogeneous transform [R p; 0 0 0 1] (R from the library's row-major 12 values).
py::array_t<double> placementsOf(Robot& r, py::handle q) {
  const VecX& X = constraintPlacements(r.sys, r.data, oneConfiguration(r, q));
  const py::ssize_t n = py::ssize_t(r.sys.constraints.size());
  requireFiniteResult(X.data(), 12 * n, "constraint_placements");
  py::array_t<double> out({n, py::ssize_t(4), py::ssize_t(4)});
  for (py::ssize_t k = 0; k < n; ++k) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) out.mutable_at(k, i, j) = X[12 * k + 3 * i + j];
      out.mutable_at(k, i, 3) = X[12 * k + 9 + i];
      out.mutable_at(k, 3, i) = 0.0;
    }
    out.mutable_at(k, 3, 3) = 1.0;
  }
  return out;
}

py::array_t<double> driftOf(Robot& r, py::handle q, py::handle v) {
  const VecX qk = oneConfiguration(r, q), vk = oneVector(v, r.sys.model.nv, "v", "nv");
  return vectorOut(constraintDrift(r.sys, r.data, qk, vk), "constraint_drift");
}

py::array_t<double> delassusInverseOf(Robot& r, py::handle q, py::handle mu) {
  const double m = readMu(mu, r.sys.mu);
  return matrixOut(delassusInverse(r.sys, r.data, oneConfiguration(r, q), m), "delassus_inverse");
}

py::tuple readState(Robot& r, py::handle state) {
  if (!py::isinstance<py::dict>(state)) throw py::type_error("state: expected a dict with keys q, v and optionally tau");
  const State s = stateFromJson(r.sys.model, toJson(state, "state"), "state");
  return py::make_tuple(toArray(s.q), toArray(s.v), toArray(s.tau));
}

const char* jointTypeText(JointType t) {
  switch (t) {
    case JointType::Revolute: return "revolute";
    case JointType::Prismatic: return "prismatic";
    case JointType::FreeFlyer: return "free_flyer";
    case JointType::Planar: return "planar";
  }
  return "";
}

py::list joints(const Robot& r) {
  py::list out;
  for (int i = 1; i < r.sys.model.numBodies(); ++i) {
    const Body& b = r.sys.model.bodies[i];
    const Joint& j = b.joint;
    py::dict d;
    d["name"] = j.name;
    d["type"] = jointTypeText(j.type);
    d["link"] = b.link;
    d["idx_q"] = j.idx_q;
    d["nq"] = j.nq;
    d["idx_v"] = j.idx_v;
    d["nv"] = j.nv;
    if (j.hasPositionLimits) d["limits"] = py::make_tuple(j.lower, j.upper);
    out.append(d);
  }
  return out;
}

py::list constraints(const Robot& r) {
  py::list out;
  for (const Constraint& c : r.sys.constraints) {
    py::dict d;
    d["name"] = c.name;
    d["link"] = c.link;
    d["type"] = c.type == ConstraintType::Weld6D ? "6d" : "3d";
    d["row"] = c.row;
    d["rows"] = c.rows();
    out.append(d);
  }
  return out;
}

std::vector<std::string> generate(const std::string& urdf, const std::string& layout, const std::string& cases,
                                  const std::string& caseName, const std::string& out, const std::string& name,
                                  const std::string& scalar, bool python) {
  // The CLI's pipeline (cli/generate.cpp): one load, every file through one atomic write.
  const emit::ScalarType type = emit::parseScalar(scalar);
  System sys;
  const emit::SolverFiles files = generateFromInputs(urdf, layout, cases, caseName, name, type, &sys);
  std::vector<emit::OutputFile> outputs = emit::solverOutputs(files);
  if (python) outputs.push_back(emit::pythonModuleOutput(sys, files, type));
  return emit::writeFiles(outputs, out);
}

}  // namespace
}  // namespace proxgen::python

PYBIND11_MODULE(_proxgen, m) {
  using namespace proxgen::python;
  using proxgen::System;
  m.doc() = "proxgen host library (use the proxgen package, not this module)";
  m.attr("version") = PROXGEN_VERSION;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const proxgen::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<Robot>(m, "System")
      .def_property_readonly("name", [](const Robot& r) { return r.sys.model.name; })
      .def_property_readonly("urdf", [](const Robot& r) { return r.sys.model.sourcePath; })
      .def_property_readonly("nq", [](const Robot& r) { return r.sys.model.nq; })
      .def_property_readonly("nv", [](const Robot& r) { return r.sys.model.nv; })
      .def_property_readonly("nc", [](const Robot& r) { return r.sys.nc; })
      .def_property_readonly("mu", [](const Robot& r) { return r.sys.mu; })
      .def_property_readonly("iterations", [](const Robot& r) { return r.sys.iterations; })
      .def_property_readonly("floating_base", [](const Robot& r) { return r.sys.model.floatingBase; })
      .def_property_readonly("gravity", [](const Robot& r) { return toArray(r.sys.model.gravity); })
      .def_property_readonly("warnings", [](const Robot& r) { return r.sys.model.warnings; })
      .def_property_readonly("joints", &joints)
      .def_property_readonly("constraints", &constraints)
      .def_property_readonly("neutral", [](const Robot& r) { return toArray(r.sys.model.neutral()); })
      .def("eval", &evalStates, py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("algorithm"), py::arg("iterations"),
           py::arg("mu"))
      .def("state", &readState, py::arg("state"))
      .def("constraint_frames", &constraintFrames, py::arg("q"), py::arg("v"))
      .def("residual", &residual, py::arg("q"), py::arg("v"), py::arg("qdd"))
      .def("inverse_dynamics", &inverseDynamicsOf, py::arg("q"), py::arg("v"), py::arg("qdd"), py::arg("lam"))
      .def("nonlinear_effects", &nonlinearEffectsOf, py::arg("q"), py::arg("v"))
      .def("mass_matrix", [](Robot& r, py::handle q) {
        return matrixOut(proxgen::crba(r.sys, r.data, oneConfiguration(r, q)), "mass_matrix");
      }, py::arg("q"))
      .def("mass_matrix_inverse", [](Robot& r, py::handle q) {
        return matrixOut(proxgen::massMatrixInverse(r.sys, r.data, oneConfiguration(r, q)), "mass_matrix_inverse");
      }, py::arg("q"))
      .def("constraint_placements", &placementsOf, py::arg("q"))
      .def("constraint_jacobian", [](Robot& r, py::handle q) {
        return matrixOut(proxgen::constraintJacobianRows(r.sys, r.data, oneConfiguration(r, q)), "constraint_jacobian");
      }, py::arg("q"))
      .def("constraint_drift", &driftOf, py::arg("q"), py::arg("v"))
      .def("delassus", [](Robot& r, py::handle q) {
        return matrixOut(proxgen::delassus(r.sys, r.data, oneConfiguration(r, q)), "delassus");
      }, py::arg("q"))
      .def("delassus_inverse", &delassusInverseOf, py::arg("q"), py::arg("mu"));

  m.def("load", [](const std::string& urdf, const std::string& layoutPath) {
    return new Robot(proxgen::loadSystem(urdf, layoutPath));
  }, py::arg("urdf"), py::arg("layout"));
  m.def("load_layout_text", [](const std::string& urdf, const std::string& text, const std::string& where) {
    const proxgen::Layout layout = proxgen::parseLayout(text, where);
    return new Robot(proxgen::bindLayout(proxgen::loadUrdf(urdf, layout.base()), layout));
  }, py::arg("urdf"), py::arg("text"), py::arg("where"));
  m.def("load_without_layout", [](const std::string& urdf, bool floating) {
    return new Robot(proxgen::loadSystemWithoutLayout(urdf, floating));
  }, py::arg("urdf"), py::arg("floating_base"));
  m.def("load_case", [](const std::string& cases, const std::string& name) {
    return new Robot(proxgen::loadCaseSystem(proxgen::loadCase(cases, name)));
  }, py::arg("cases"), py::arg("name"));
  m.def("case_names", [](const std::string& cases) {
    std::vector<std::string> names;
    for (const proxgen::Case& c : proxgen::loadCases(cases)) names.push_back(c.name);
    return names;
  }, py::arg("cases"));
  m.def("case_urdf", [](const std::string& cases, const std::string& name) {
    return proxgen::loadCase(cases, name).urdfPath;
  }, py::arg("cases"), py::arg("name"));
  m.def("generate", &generate, py::arg("urdf"), py::arg("layout"), py::arg("cases"), py::arg("case"), py::arg("out"),
        py::arg("name"), py::arg("scalar"), py::arg("python"));
}

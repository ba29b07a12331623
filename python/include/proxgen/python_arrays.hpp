// numpy inputs and outputs shared by the `proxgen` package (python/src) and the
// generated solver modules (templates/python_module.cpp.tpl): one policy for
// bad input (docs/python.md, "Bad input"), every failure a Python exception
// naming the argument and what was expected, never a crash.
//
// Inputs: anything numpy turns into an array of real numbers (float, integer
// dtypes, lists); bool, complex, object and string dtypes are a TypeError.
// A C-contiguous, aligned array of the solver's scalar is read in place (it is
// never written, so read-only arrays are fine); anything else is copied once.
// Outputs are always new arrays.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstddef>
#include <string>

namespace proxgen::python {

namespace py = pybind11;

inline constexpr double kMaxIterations = 1e6;  // as `proxgen eval --iterations`

inline std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// `obj` as a C-contiguous array of Scalar, viewed in place when it already is one.
template <class Scalar>
py::array_t<Scalar> asArray(py::handle obj, const char* arg) {
  constexpr int flags = py::array::c_style;
  if (py::array_t<Scalar, flags>::check_(obj)) {
    auto a = py::reinterpret_borrow<py::array_t<Scalar, flags>>(obj);
    if (a.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) return a;
  }
  py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error(std::string(arg) + ": expected an array of real numbers, got " +
                               std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(std::string(arg) + ": expected real numbers (a float or integer dtype), got dtype " +
                         std::string(py::str(a.dtype())));
  return py::array_t<Scalar, flags | py::array::forcecast>::ensure(a);
}

/// Shape (n,) -> batch 0 (one state), (N, n) -> batch N >= 1; anything else a ValueError.
/// `batch` is -1 on entry for the first argument, then must agree.
template <class Scalar>
const Scalar* checkShape(const py::array_t<Scalar>& a, py::ssize_t n, const char* arg, py::ssize_t& batch,
                         const char* sizeName) {
  py::ssize_t got = -2;
  if (a.ndim() == 1 && a.shape(0) == n) got = 0;
  if (a.ndim() == 2 && a.shape(1) == n && a.shape(0) >= 1) got = a.shape(0);
  if (got == -2)
    throw py::value_error(std::string(arg) + ": expected shape (" + sizeName + ",) = (" + std::to_string(n) +
                          ",) or (N, " + std::to_string(n) + ") with N >= 1, got " + shapeText(a));
  if (batch != -1 && got != batch)
    throw py::value_error(std::string(arg) + ": has shape " + shapeText(a) +
                          (batch == 0 ? std::string(", but q is one state") : ", but q has " + std::to_string(batch) + " states"));
  batch = got;
  return a.data();
}

template <class Scalar>
void checkFinite(const Scalar* x, py::ssize_t count, py::ssize_t width, const char* arg) {
  for (py::ssize_t k = 0; k < count; ++k)
    if (!std::isfinite(x[k])) {
      std::string where = width == count ? "[" + std::to_string(k) + "]"
                                         : "[" + std::to_string(k / width) + ", " + std::to_string(k % width) + "]";
      throw py::value_error(std::string(arg) + where + " is not finite");
    }
}

/// The three inputs of a solve, checked: same batch, the right widths, finite.
template <class Scalar>
struct States {
  py::array_t<Scalar> qa, va, ta;  // keep copies alive
  const Scalar *q = nullptr, *v = nullptr, *tau = nullptr;
  py::ssize_t batch = -1;  // 0: one state, else N
  py::ssize_t count() const { return batch == 0 ? 1 : batch; }
};

template <class Scalar>
States<Scalar> readStates(py::handle q, py::handle v, py::handle tau, py::ssize_t nq, py::ssize_t nv) {
  States<Scalar> s;
  s.qa = asArray<Scalar>(q, "q");
  s.va = asArray<Scalar>(v, "v");
  s.ta = asArray<Scalar>(tau, "tau");
  s.q = checkShape(s.qa, nq, "q", s.batch, "nq");
  s.v = checkShape(s.va, nv, "v", s.batch, "nv");
  s.tau = checkShape(s.ta, nv, "tau", s.batch, "nv");
  checkFinite(s.q, s.count() * nq, nq, "q");
  checkFinite(s.v, s.count() * nv, nv, "v");
  checkFinite(s.tau, s.count() * nv, nv, "tau");
  return s;
}

/// The free-flyer quaternion [qx qy qz qw] at q[at..at+3] copied into `out`
/// normalised, as `proxgen eval` does; a zero norm is a ValueError.
template <class Scalar>
void normalisedConfiguration(const Scalar* q, py::ssize_t nq, int at, py::ssize_t state, bool batched, Scalar* out) {
  for (py::ssize_t k = 0; k < nq; ++k) out[k] = q[k];
  if (at < 0) return;
  const double n = std::sqrt(double(q[at]) * q[at] + double(q[at + 1]) * q[at + 1] + double(q[at + 2]) * q[at + 2] +
                             double(q[at + 3]) * q[at + 3]);
  if (!(n > 1e-8))
    throw py::value_error(std::string("q") + (batched ? "[" + std::to_string(state) + "]" : std::string()) +
                          ": the free-flyer quaternion [qx qy qz qw] at q[" + std::to_string(at) + ":" +
                          std::to_string(at + 4) + "] has zero norm");
  for (int k = 0; k < 4; ++k) out[at + k] = Scalar(q[at + k] / n);
}

/// mu: None -> the default, else a finite real > 0.
inline double readMu(py::handle mu, double fallback) {
  if (mu.is_none()) return fallback;
  if (PyBool_Check(mu.ptr())) throw py::type_error("mu: expected a real number > 0, got bool");
  const double x = PyFloat_AsDouble(mu.ptr());
  if (x == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    throw py::type_error("mu: expected a real number > 0, got " +
                         std::string(py::str(py::type::handle_of(mu).attr("__name__"))));
  }
  if (!std::isfinite(x)) throw py::value_error("mu: is not finite");
  if (!(x > 0)) throw py::value_error("mu: the penalty must be > 0, got " + std::string(py::repr(mu)));
  return x;
}

/// iterations: None -> the default, else an integer in [0, 1e6].
inline int readIterations(py::handle k, int fallback) {
  if (k.is_none()) return fallback;
  if (PyBool_Check(k.ptr()) || !PyIndex_Check(k.ptr()))
    throw py::type_error("iterations: expected an integer in [0, 1000000], got " +
                         std::string(py::str(py::type::handle_of(k).attr("__name__"))));
  int overflow = 0;
  py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(k.ptr()));
  if (!index) throw py::error_already_set();
  const long long x = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0 || x < 0 || x > (long long)kMaxIterations)
    throw py::value_error("iterations: " + std::string(py::repr(k)) + " is outside [0, 1000000]");
  return int(x);
}

/// A new C-contiguous array of shape (n,) (batch 0) or (batch, n). Straight
/// through numpy's PyArray_NewFromDescr: pybind11's array constructors build
/// shape and stride vectors on the heap, a tenth of a single call's overhead.
template <class Scalar>
py::array_t<Scalar> newOutput(py::ssize_t batch, py::ssize_t n) {
  auto& api = py::detail::npy_api::get();
  Py_intptr_t dims[2] = {batch, n};
  const int nd = batch == 0 ? 1 : 2;
  PyObject* descr = py::dtype::of<Scalar>().release().ptr();  // stolen by the call
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, descr, nd, batch == 0 ? dims + 1 : dims, nullptr, nullptr,
                                          0, nullptr);
  if (!a) throw py::error_already_set();
  return py::reinterpret_steal<py::array_t<Scalar>>(a);
}

}  // namespace proxgen::python

// proxgen eval --compute QUANTITY: the dynamics library (docs/dynamics.md) on
// states read from JSON, printed as JSON keyed by joint and constraint names,
// so the numbers can be cross-checked against another library. Vectors are
// objects keyed by joint (a number, or a list of 6 for a free flyer) or by
// constraint (a list of its rows); matrices carry their row and column names
// ("joint" for a one-dof joint, "joint[k]" for a free flyer's slot k,
// "constraint[r]" for a constraint's row r) and their rows as lists.
//
// inverse_dynamics reads two more keys of each state object: qdd (keyed by
// joint, every joint) and lambda (keyed by constraint, a list of its rows;
// optional, missing constraints push with 0). wrenches reads lambda alone (required,
// same form): each constraint's wrench on the robot in world axes, force and
// torque about the constraint frame's origin, the solvers' sign (the constraint
// force on the robot is -J^T lambda). No other quantity accepts them.
//
// derivatives (docs/derivatives.md): the converged constrained solution qdd,
// lambda (proxPV with --mu and --iterations, default 200: the proximal limit)
// and its six derivative matrices; columns of d/dq are tangent directions
// q (+) dq, named like the velocity slots.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/derivatives.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "cli/commands.hpp"
#include "model/error.hpp"
#include "model/input.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"

namespace proxgen::cli {
namespace {

using json = nlohmann::json;
using ordered_json = nlohmann::ordered_json;

enum class Quantity { InverseDynamics, NonlinearEffects, MassMatrix, MassMatrixInverse, Placements, Jacobian, Drift, Delassus, DelassusInverse, Wrenches, Derivatives };

struct QuantityName {
  const char* name;
  Quantity q;
};
const QuantityName kQuantities[] = {{"inverse_dynamics", Quantity::InverseDynamics}, {"nonlinear_effects", Quantity::NonlinearEffects},
                                    {"mass_matrix", Quantity::MassMatrix},           {"mass_matrix_inverse", Quantity::MassMatrixInverse},
                                    {"placements", Quantity::Placements},            {"jacobian", Quantity::Jacobian},
                                    {"drift", Quantity::Drift},                      {"delassus", Quantity::Delassus},
                                    {"delassus_inverse", Quantity::DelassusInverse}, {"wrenches", Quantity::Wrenches},
                                    {"derivatives", Quantity::Derivatives}};

// The iterations of --compute derivatives when --iterations is not given: the
// converged solve (K = 200, as tests/algorithms/test_derivatives.cpp).
constexpr int kConvergedIterations = 200;

Quantity parseQuantity(const std::string& name) {
  std::string valid;
  for (const QuantityName& k : kQuantities) {
    if (name == k.name) return k.q;
    valid += valid.empty() ? k.name : fmt::format(", {}", k.name);
  }
  fail("command line", "--compute", fmt::format("unknown quantity {} (expected one of {})", quoted(name), valid));
}

double finiteNumber(const json& x, const std::string& where, const std::string& element) {
  if (!x.is_number()) fail(where, element, "expected a number");
  // Finite and at most the inputs' magnitude bound, as every number of a state (model/input.hpp).
  return requireMagnitude(where, element, x.get<double>());
}

// n slots at x[at]: a number (n == 1) or a list of n numbers.
void readSlots(const json& j, int n, VecX& x, int at, const std::string& where, const std::string& element, bool alwaysList) {
  if (n == 1 && !alwaysList) {
    x[at] = finiteNumber(j, where, element);
    return;
  }
  if (!j.is_array() || int(j.size()) != n) fail(where, element, fmt::format("expected a list of {} numbers", n));
  for (int k = 0; k < n; ++k) x[at + k] = finiteNumber(j[k], where, fmt::format("{}[{}]", element, k));
}

VecX qddFromJson(const Model& m, const json& j, const std::string& where) {
  if (!j.is_object()) fail(where, "qdd", "expected an object keyed by joint name");
  for (const auto& item : j.items())
    if (m.findJointBody(item.key()) < 1) fail(where, fmt::format("qdd.{}", quoted(item.key())), "no moving joint of that name");
  VecX qdd = VecX::Zero(m.nv);
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& jt = m.bodies[i].joint;
    const std::string element = fmt::format("qdd.{}", quoted(jt.name));
    if (!j.contains(jt.name)) fail(where, element, "missing");
    readSlots(j.at(jt.name), jt.nv, qdd, jt.idx_v, where, element, false);
  }
  return qdd;
}

VecX lambdaFromJson(const System& sys, const json& j, const std::string& where) {
  if (!j.is_object()) fail(where, "lambda", "expected an object keyed by constraint name");
  for (const auto& item : j.items())
    if (sys.findConstraint(item.key()) < 0) fail(where, fmt::format("lambda.{}", quoted(item.key())), "no constraint of that name");
  VecX lambda = VecX::Zero(sys.nc);
  for (const Constraint& c : sys.constraints)
    if (j.contains(c.name)) readSlots(j.at(c.name), c.rows(), lambda, c.row, where, fmt::format("lambda.{}", quoted(c.name)), true);
  return lambda;
}

// --- output ------------------------------------------------------------------

std::vector<std::string> dofNames(const Model& m) {
  std::vector<std::string> out;
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    for (int k = 0; k < j.nv; ++k) out.push_back(j.nv == 1 ? j.name : fmt::format("{}[{}]", j.name, k));
  }
  return out;
}

std::vector<std::string> rowNames(const System& sys) {
  std::vector<std::string> out;
  for (const Constraint& c : sys.constraints)
    for (int r = 0; r < c.rows(); ++r) out.push_back(fmt::format("{}[{}]", c.name, r));
  return out;
}

ordered_json matrixJson(const MatX& A, const std::vector<std::string>& rows, const std::vector<std::string>& cols) {
  ordered_json values = ordered_json::array();
  for (Eigen::Index r = 0; r < A.rows(); ++r) {
    ordered_json row = ordered_json::array();
    for (Eigen::Index c = 0; c < A.cols(); ++c) row.push_back(A(r, c));
    values.push_back(row);
  }
  return {{"rows", rows}, {"cols", cols}, {"values", values}};
}

// Keyed by joint name, in joint order: a number, or a list for a free flyer.
ordered_json jointsJson(const Model& m, const VecX& x) {
  ordered_json out = ordered_json::object();
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    if (j.nv == 1) {
      out[j.name] = x[j.idx_v];
      continue;
    }
    ordered_json slots = ordered_json::array();
    for (int k = 0; k < j.nv; ++k) slots.push_back(x[j.idx_v + k]);
    out[j.name] = slots;
  }
  return out;
}

// Keyed by constraint name, in layout order, always a list of its rows.
ordered_json constraintsJson(const System& sys, const VecX& x) {
  ordered_json out = ordered_json::object();
  for (const Constraint& c : sys.constraints) {
    ordered_json rows = ordered_json::array();
    for (int r = 0; r < c.rows(); ++r) rows.push_back(x[c.row + r]);
    out[c.name] = rows;
  }
  return out;
}

ordered_json placementsJson(const System& sys, const VecX& X) {
  ordered_json out = ordered_json::object();
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    ordered_json R = ordered_json::array();
    for (int r = 0; r < 3; ++r) R.push_back({X[12 * k + 3 * r], X[12 * k + 3 * r + 1], X[12 * k + 3 * r + 2]});
    out[sys.constraints[k].name] = {{"rotation", R}, {"position", {X[12 * k + 9], X[12 * k + 10], X[12 * k + 11]}}};
  }
  return out;
}

// Keyed by constraint name: the force and the torque (about the frame's origin), world axes.
ordered_json wrenchesJson(const System& sys, const VecX& W) {
  ordered_json out = ordered_json::object();
  for (std::size_t k = 0; k < sys.constraints.size(); ++k)
    out[sys.constraints[k].name] = {{"force", {W[6 * k], W[6 * k + 1], W[6 * k + 2]}},
                                    {"torque", {W[6 * k + 3], W[6 * k + 4], W[6 * k + 5]}}};
  return out;
}

ordered_json derivativesJson(const System& sys, Data& d, DerivativeData& dd, const State& s, double mu, int iterations) {
  const Model& m = sys.model;
  constrainedDynamicsDerivatives(sys, d, dd, s.q, s.v, s.tau, mu, iterations);
  const std::vector<std::string> dofs = dofNames(m), rows = rowNames(sys);
  return {{"mu", mu},
          {"iterations", iterations},
          {"qdd", jointsJson(m, dd.qdd)},
          {"lambda", constraintsJson(sys, dd.lambda)},
          {"dqdd_dq", matrixJson(dd.dqdd_dq, dofs, dofs)},
          {"dqdd_dv", matrixJson(dd.dqdd_dv, dofs, dofs)},
          {"dqdd_dtau", matrixJson(dd.dqdd_dtau, dofs, dofs)},
          {"dlambda_dq", matrixJson(dd.dlambda_dq, rows, dofs)},
          {"dlambda_dv", matrixJson(dd.dlambda_dv, rows, dofs)},
          {"dlambda_dtau", matrixJson(dd.dlambda_dtau, rows, dofs)}};
}

ordered_json computeOne(const System& sys, Data& d, DerivativeData& dd, Quantity what, const State& s, const VecX& qdd,
                        const VecX* lambda, double mu, int iterations) {
  const Model& m = sys.model;
  switch (what) {
    case Quantity::InverseDynamics: return {{"tau", jointsJson(m, inverseDynamics(sys, d, s.q, s.v, qdd, lambda))}};
    case Quantity::NonlinearEffects: return {{"h", jointsJson(m, nonLinearEffects(sys, d, s.q, s.v))}};
    case Quantity::MassMatrix: return {{"M", matrixJson(crba(sys, d, s.q), dofNames(m), dofNames(m))}};
    case Quantity::MassMatrixInverse: return {{"Minv", matrixJson(massMatrixInverse(sys, d, s.q), dofNames(m), dofNames(m))}};
    case Quantity::Placements: return {{"placements", placementsJson(sys, constraintPlacements(sys, d, s.q))}};
    case Quantity::Jacobian: return {{"J", matrixJson(constraintJacobianRows(sys, d, s.q), rowNames(sys), dofNames(m))}};
    case Quantity::Drift: return {{"gamma", constraintsJson(sys, constraintDrift(sys, d, s.q, s.v))}};
    case Quantity::Delassus: return {{"G", matrixJson(delassus(sys, d, s.q), rowNames(sys), rowNames(sys))}};
    case Quantity::DelassusInverse:
      return {{"mu", mu}, {"Ginv", matrixJson(delassusInverse(sys, d, s.q, mu), rowNames(sys), rowNames(sys))}};
    case Quantity::Wrenches: return {{"wrenches", wrenchesJson(sys, constraintWrenches(sys, d, s.q, *lambda))}};
    case Quantity::Derivatives: return derivativesJson(sys, d, dd, s, mu, iterations);
  }
  return {};
}

// Inputs are bounded (model/input.hpp), yet a product can still overflow: no
// non-finite number is printed (JSON would hold it as null) or exits 0.
bool allFiniteJson(const ordered_json& x) {
  if (x.is_number_float()) return std::isfinite(x.get<double>());
  if (x.is_structured())
    for (const ordered_json& e : x)
      if (!allFiniteJson(e)) return false;
  return true;
}

}  // namespace

void runCompute(const std::string& urdf, const std::string& layout, const std::string& statePath, const std::string& quantity, double mu,
                int iterations) {
  const Quantity what = parseQuantity(quantity);
  const System sys = loadSystem(urdf, layout);
  if (!(mu > 0)) mu = sys.mu;
  if (iterations >= 0 && what != Quantity::Derivatives)
    fail("command line", "--iterations", fmt::format("applies to --compute derivatives only (this is {})", quantity));
  if (iterations < 0) iterations = kConvergedIterations;
  const json file = readStateJson(statePath);
  const bool isList = file.is_array();
  const std::size_t count = isList ? file.size() : 1;
  Data d(sys);
  DerivativeData dd(sys);
  ordered_json results = ordered_json::array();
  for (std::size_t k = 0; k < count; ++k) {
    const std::string where = isList ? fmt::format("{}: [{}]", statePath, k) : statePath;
    json object = isList ? file[k] : file;
    VecX qdd = VecX::Zero(sys.model.nv), lambda;
    bool hasLambda = false;
    if (object.is_object()) {
      if (object.contains("qdd") && what != Quantity::InverseDynamics)
        fail(where, "qdd", fmt::format("only --compute inverse_dynamics reads qdd (this is {})", quantity));
      if (object.contains("lambda") && what != Quantity::InverseDynamics && what != Quantity::Wrenches)
        fail(where, "lambda", fmt::format("only --compute inverse_dynamics and wrenches read lambda (this is {})", quantity));
      if (what == Quantity::Wrenches) {
        if (!object.contains("lambda")) fail(where, "lambda", "missing (wrenches needs the multipliers, keyed by constraint)");
        lambda = lambdaFromJson(sys, object.at("lambda"), where);
        hasLambda = true;
        object.erase("lambda");
      }
      if (what == Quantity::InverseDynamics) {
        if (!object.contains("qdd")) fail(where, "qdd", "missing (inverse_dynamics needs the acceleration)");
        qdd = qddFromJson(sys.model, object.at("qdd"), where);
        object.erase("qdd");
        if (object.contains("lambda")) {
          lambda = lambdaFromJson(sys, object.at("lambda"), where);
          hasLambda = true;
          object.erase("lambda");
        }
      }
    }
    const State s = stateFromJson(sys.model, object, where);
    if (what == Quantity::Wrenches && !hasLambda) fail(where, "lambda", "missing (wrenches needs the multipliers)");
    ordered_json r = {{"compute", quantity}};
    r.update(computeOne(sys, d, dd, what, s, qdd, hasLambda ? &lambda : nullptr, mu, iterations));
    if (!allFiniteJson(r)) fail(where, quantity, "is not finite at this state (an intermediate overflowed)");
    results.push_back(r);
  }
  // Printed only once everything succeeded: an error leaves stdout empty.
  const std::string out = (isList ? results : results.at(0)).dump(2) + "\n";
  std::fputs(out.c_str(), stdout);
}

}  // namespace proxgen::cli

#include "model/functions.hpp"

#include "model/error.hpp"

namespace proxgen {

namespace {

struct Named {
  Function f;
  const char* name;
};

// allFunctions() order: the solvers, the joint-space quantities, the
// constraint kinematics, the Delassus operator, the constraints' world wrenches,
// the derivatives of the dynamics (docs/derivatives.md).
constexpr Named kFunctions[] = {
    {Function::ConstrainedAba, "constrained_aba"},
    {Function::ProxPv, "prox_pv"},
    {Function::InverseDynamics, "inverse_dynamics"},
    {Function::NonlinearEffects, "nonlinear_effects"},
    {Function::MassMatrix, "mass_matrix"},
    {Function::MassMatrixInverse, "mass_matrix_inverse"},
    {Function::ConstraintPlacements, "constraint_placements"},
    {Function::ConstraintJacobian, "constraint_jacobian"},
    {Function::ConstraintDrift, "constraint_drift"},
    {Function::Delassus, "delassus"},
    {Function::DelassusInverse, "delassus_inverse"},
    {Function::ConstraintWrenches, "constraint_wrenches"},
    {Function::InverseDynamicsDerivatives, "inverse_dynamics_derivatives"},
    {Function::ForwardDynamicsDerivatives, "forward_dynamics_derivatives"},
    {Function::ConstrainedDynamicsDerivatives, "constrained_dynamics_derivatives"},
};

}  // namespace

const std::vector<Function>& allFunctions() {
  static const std::vector<Function> all = [] {
    std::vector<Function> v;
    for (const Named& n : kFunctions) v.push_back(n.f);
    return v;
  }();
  return all;
}

const char* functionName(Function f) {
  for (const Named& n : kFunctions)
    if (n.f == f) return n.name;
  return "?";
}

std::string functionNameList() {
  std::string s;
  for (const Named& n : kFunctions) s += (s.empty() ? "" : ", ") + std::string(n.name);
  return s;
}

FunctionSet::FunctionSet() {
  add(Function::ConstrainedAba);
  add(Function::ProxPv);
}

FunctionSet FunctionSet::none() {
  FunctionSet s;
  s.bits_ = 0;
  return s;
}

FunctionSet FunctionSet::all() {
  FunctionSet s = none();
  for (Function f : allFunctions()) s.add(f);
  return s;
}

std::vector<std::string> FunctionSet::names() const {
  std::vector<std::string> out;
  for (Function f : allFunctions())
    if (has(f)) out.push_back(functionName(f));
  return out;
}

bool parseFunctionName(const std::string& name, Function& out) {
  for (const Named& n : kFunctions)
    if (name == n.name) {
      out = n.f;
      return true;
    }
  return false;
}

FunctionSet parseFunctionList(const std::string& list, const std::string& file, const std::string& element) {
  if (list == "all") return FunctionSet::all();
  FunctionSet set = FunctionSet::none();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = list.find(',', start);
    const std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    Function f;
    if (!parseFunctionName(name, f))
      fail(file, element, "unknown function " + quoted(name) + " (valid: " + functionNameList() + ", or all)");
    if (set.has(f)) fail(file, element, "function " + quoted(name) + " is listed twice");
    set.add(f);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return set;
}

}  // namespace proxgen

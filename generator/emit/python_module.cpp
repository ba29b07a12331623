#include "emit/python_module.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <utility>

#include "model/error.hpp"
#include "model/layout.hpp"

namespace proxgen::emit {
namespace {

namespace fs = std::filesystem;

const char* const kPythonModuleTemplate =
#include "../../templates/python_module.cpp.tpl"
    ;

const char* jointTypeText(JointClass c) {
  if (c == JointClass::FreeFlyer) return "free_flyer";
  if (c == JointClass::Planar) return "planar";
  switch (c) {
    case JointClass::PrismaticX:
    case JointClass::PrismaticY:
    case JointClass::PrismaticZ:
    case JointClass::PrismaticAxis: return "prismatic";
    default: return "revolute";
  }
}

// The module's binding of one library function (proxgen/python_module.hpp).
std::string bindingOf(Function f, const std::string& ns) {
  const std::string fn = "&" + ns + "::" + functionName(f);
  const std::string b = "  proxgen::python::";
  switch (f) {
    case Function::ConstrainedAba:
    case Function::ProxPv:
      return fmt::format("{}bindSolve<Solver, {}>(m, kInfo, \"{}\");\n", b, fn, functionName(f));
    case Function::InverseDynamics: return fmt::format("{}bindInverseDynamics<Solver>(m, kInfo, {});\n", b, fn);
    case Function::NonlinearEffects: return fmt::format("{}bindNonlinearEffects<Solver>(m, kInfo, {});\n", b, fn);
    case Function::MassMatrix:
      return fmt::format("{}bindMatrixOfQ<Solver>(m, kInfo, \"mass_matrix\", {}, Solver::nv, Solver::nv,\n"
                         "      \"(q) -> M (nv, nv) or (N, nv, nv): the joint-space inertia matrix.\");\n", b, fn);
    case Function::MassMatrixInverse:
      return fmt::format("{}bindMatrixOfQ<Solver>(m, kInfo, \"mass_matrix_inverse\", {}, Solver::nv, Solver::nv,\n"
                         "      \"(q) -> M^-1 (nv, nv) or (N, nv, nv).\");\n", b, fn);
    case Function::ConstraintPlacements: return fmt::format("{}bindConstraintPlacements<Solver>(m, kInfo, {});\n", b, fn);
    case Function::ConstraintJacobian:
      return fmt::format("{}bindScheduledMatrixOfQ<Solver>(m, kInfo, \"constraint_jacobian\", {}, Solver::nc, Solver::nv,\n"
                         "      \"(q, active=None) -> J (nc, nv) or (N, nc, nv): the constraint rows, layout order.\");\n", b, fn);
    case Function::ConstraintDrift: return fmt::format("{}bindConstraintDrift<Solver>(m, kInfo, {});\n", b, fn);
    case Function::Delassus:
      return fmt::format("{}bindScheduledMatrixOfQ<Solver>(m, kInfo, \"delassus\", {}, Solver::nc, Solver::nc,\n"
                         "      \"(q, active=None) -> G = J M^-1 J^T (nc, nc) or (N, nc, nc).\");\n", b, fn);
    case Function::DelassusInverse: return fmt::format("{}bindDelassusInverse<Solver>(m, kInfo, {});\n", b, fn);
    case Function::ConstraintWrenches: return fmt::format("{}bindConstraintWrenches<Solver>(m, kInfo, {});\n", b, fn);
    case Function::InverseDynamicsDerivatives:
      return fmt::format("{}bindInverseDynamicsDerivatives<Solver>(m, kInfo, {});\n", b, fn);
    case Function::ForwardDynamicsDerivatives:
      return fmt::format("{}bindForwardDynamicsDerivatives<Solver>(m, kInfo, {});\n", b, fn);
    case Function::ConstrainedDynamicsDerivatives:
      return fmt::format("{}bindConstrainedDynamicsDerivatives<Solver>(m, kInfo, {});\n", b, fn);
  }
  return "";
}

}  // namespace

std::string cppStringLiteral(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    // Octal escapes stop after three digits, so a following digit cannot join them.
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\' && c != '?')
      out += char(c);
    else
      out += fmt::format("\\{:03o}", c);
  }
  return out + "\"";
}

PythonModuleFile emitPythonModule(const Plan& plan, const FunctionSet& functions) {
  std::string joints, constraints;
  int quaternionAt = -1;
  for (std::size_t i = 1; i < plan.bodies.size(); ++i) {
    const BodyPlan& b = plan.bodies[i];
    if (b.jointClass == JointClass::FreeFlyer) quaternionAt = b.idx_q + 3;
    joints += fmt::format("        {{{}, \"{}\", {}, {}, {}, {}}},\n", cppStringLiteral(b.joint), jointTypeText(b.jointClass),
                          b.idx_q, b.nq, b.idx_v, b.nv);
  }
  for (const ConstraintPlan& c : plan.constraints)
    constraints += fmt::format("        {{{}, \"{}\", {}, {}}},\n", cppStringLiteral(c.name), c.weld ? "6d" : "3d", c.row, c.rows);
  std::string bindings, names, list;
  for (Function fn : allFunctions()) {
    if (!functions.has(fn)) continue;
    const std::string b = bindingOf(fn, plan.name);
    if (b.empty()) continue;
    bindings += b;
    names += fmt::format("\n      \"{}\",", functionName(fn));
    // The header comment's list, wrapped at 80 columns.
    const std::string item = std::string(functionName(fn));
    const std::size_t line = list.size() - (list.rfind('\n') == std::string::npos ? 0 : list.rfind('\n') + 1);
    if (!list.empty()) list += line + item.size() + 5 > 80 ? ",\n// " : ", ";
    list += item;
  }
  if (!names.empty()) names.pop_back();
  bindings += fmt::format("  m.attr(\"functions\") = pybind11::make_tuple({});\n", names);
  PythonModuleFile f;
  f.name = plan.name + "_python.cpp";
  f.text = fmt::format(fmt::runtime(kPythonModuleTemplate), fmt::arg("version", PROXGEN_VERSION), fmt::arg("name", plan.name),
                       fmt::arg("scalar", plan.scalar == ScalarType::Float ? "float" : "double"),
                       fmt::arg("joints", joints), fmt::arg("constraints", constraints),
                       fmt::arg("quaternion_at", quaternionAt), fmt::arg("bindings", bindings),
                       fmt::arg("function_list", list.empty() ? std::string("no function") : list));
  return f;
}

OutputFile pythonModuleOutput(const System& sys, const SolverFiles& files, ScalarType scalar) {
  // The header's stem is the plan's (already sanitised) name.
  const std::string name = fs::path(files.headerName).stem().string();
  PythonModuleFile f = emitPythonModule(makePlan(sys, name, scalar), sys.functions);
  return OutputFile{std::move(f.name), std::move(f.text)};
}

}  // namespace proxgen::emit

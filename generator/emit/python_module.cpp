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

PythonModuleFile emitPythonModule(const Plan& plan) {
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
  PythonModuleFile f;
  f.name = plan.name + "_python.cpp";
  f.text = fmt::format(fmt::runtime(kPythonModuleTemplate), fmt::arg("version", PROXGEN_VERSION), fmt::arg("name", plan.name),
                       fmt::arg("scalar", plan.scalar == ScalarType::Float ? "float" : "double"),
                       fmt::arg("joints", joints), fmt::arg("constraints", constraints),
                       fmt::arg("quaternion_at", quaternionAt));
  return f;
}

OutputFile pythonModuleOutput(const System& sys, const SolverFiles& files, ScalarType scalar) {
  // The header's stem is the plan's (already sanitised) name.
  const std::string name = fs::path(files.headerName).stem().string();
  PythonModuleFile f = emitPythonModule(makePlan(sys, name, scalar));
  return OutputFile{std::move(f.name), std::move(f.text)};
}

}  // namespace proxgen::emit

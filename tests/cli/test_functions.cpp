// The function selection of `generate` (layout `functions:`, --functions): the
// files hold exactly the selected entry points and only the helpers they call;
// --functions overrides the layout's list and is recorded in the banner; the
// two solvers named explicitly print what the default prints.
#include <gtest/gtest.h>

#include <string>

#include "emit/generate.hpp"
#include "model/error.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

SolverFiles arm(const std::string& functions) {
  const std::string dir = test::sourceDir() + "/generated/arm";
  GenerateOptions g;
  g.urdf = dir + "/arm.urdf";
  g.layout = dir + "/layout.yaml";
  g.name = "arm";
  g.functions = functions;
  return generateFiles(g);
}

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

// The text without its banner's "regenerate with" command line.
std::string withoutCommand(const std::string& text) {
  const std::size_t at = text.find("proxgen generate ");
  if (at == std::string::npos) return text;
  return text.substr(0, at) + text.substr(text.find('\n', at));
}

TEST(FunctionSelection, OnlyMassMatrixPrintsNothingElse) {
  const SolverFiles f = arm("mass_matrix");
  EXPECT_TRUE(has(f.header, "void mass_matrix(const Scalar* q, Workspace& w, Scalar* M) noexcept;"));
  for (const char* absent : {"constrained_aba(", "prox_pv(", "inverse_dynamics(", "mass_matrix_inverse("}) {
    EXPECT_FALSE(has(f.header, absent)) << absent;
    EXPECT_FALSE(has(f.source, absent)) << absent;
  }
  // No velocity: kinematics(q, v, w) is not printed; the joint transforms are.
  EXPECT_FALSE(has(f.source, "void kinematics("));
  EXPECT_TRUE(has(f.source, "void joint_transforms(const Scalar* q, Workspace& w) noexcept {"));
  EXPECT_TRUE(has(f.source, "  joint_transforms(q, w);"));
  EXPECT_TRUE(has(f.header, "//   mass_matrix: "));
  EXPECT_FALSE(has(f.header, "//   constrained_aba: "));
}

// inverse_dynamics sweeps from (q, v, qdd) itself (pass_inverse_dynamics.cpp):
// alone it prints neither the solvers' kinematics helper nor the solvers;
// nonlinear_effects calls kinematics (forward_dynamics_derivatives reads its state).
TEST(FunctionSelection, InverseDynamicsHasItsOwnSweepNotTheSolvers) {
  const SolverFiles f = arm("inverse_dynamics");
  EXPECT_TRUE(has(f.header, "tau = M(q) qdd + h(q, v) + J(q)^T lambda"));  // the sign, in the header
  EXPECT_FALSE(has(f.source, "void kinematics("));
  EXPECT_FALSE(has(f.source, "kinematics(q, v, w);"));
  EXPECT_TRUE(has(f.source, "rnea_forward_"));
  EXPECT_FALSE(has(f.source, "void joint_transforms("));
  EXPECT_FALSE(has(f.source, "eliminate_free_bodies"));
  EXPECT_FALSE(has(f.header, "prox_pv("));
  EXPECT_TRUE(has(f.header, "--functions inverse_dynamics"));  // recorded in the banner's command
  const SolverFiles h = arm("nonlinear_effects");
  EXPECT_TRUE(has(h.source, "void kinematics("));
  EXPECT_TRUE(has(h.source, "  kinematics(q, v, w);"));
}

TEST(FunctionSelection, TheTwoSolversNamedArePrintedAsTheDefault) {
  const SolverFiles def = arm(""), named = arm("prox_pv,constrained_aba");
  EXPECT_EQ(withoutCommand(def.header), withoutCommand(named.header));
  EXPECT_EQ(withoutCommand(def.source), withoutCommand(named.source));
  EXPECT_NE(def.header, named.header);  // the banner says --functions
}

TEST(FunctionSelection, EveryJointSpaceFunctionIsDeclaredOnce) {
  const SolverFiles f = arm("constrained_aba,prox_pv,inverse_dynamics,nonlinear_effects,mass_matrix,mass_matrix_inverse");
  for (const char* decl : {"void inverse_dynamics(", "void nonlinear_effects(", "void mass_matrix(",
                           "void mass_matrix_inverse(", "void constrained_aba(", "void prox_pv("}) {
    const std::size_t at = f.header.find(decl);
    EXPECT_NE(at, std::string::npos) << decl;
    EXPECT_EQ(f.header.find(decl, at + 1), std::string::npos) << decl;
  }
}

TEST(FunctionSelection, AnUnknownNameIsAnErrorNamingTheValidOnes) {
  const std::string m = test::errorOf([] { arm("mass_matrix,rnea"); });
  for (const char* part : {"command line", "--functions", "'rnea'", "inverse_dynamics", "mass_matrix_inverse", "or all"})
    EXPECT_TRUE(has(m, part)) << part << " not in: " << m;
}

// A function without a pass in this emitter is an error, not left out.
TEST(FunctionSelection, EveryNamedFunctionIsPrintedOrRefused) {
  for (Function f : allFunctions()) {
    const std::string name = functionName(f);
    try {
      const SolverFiles files = arm(name);
      EXPECT_TRUE(has(files.header, "void " + name + "(")) << name;
    } catch (const Error& e) {
      EXPECT_TRUE(has(e.what(), "'" + name + "' is not generated")) << e.what();
    }
  }
}

}  // namespace
}  // namespace proxgen::emit

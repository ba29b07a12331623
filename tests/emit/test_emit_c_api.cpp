// The C interface's names and types (emit/c_api.cpp; docs/design.md "The C
// interface"): the prefix is the solver name unless a C name it forms is
// reserved, a float solver's C functions take float, and NAME_c.h declares
// exactly the functions the solver holds.
#include <gtest/gtest.h>

#include <string>

#include "emit/c_api.hpp"
#include "emit/generate.hpp"
#include "emit/plan.hpp"
#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

System quadruped() {
  const std::string g = test::sourceDir() + "/generated/quadruped/";
  return loadSystem(g + "quadruped.urdf", g + "layout.yaml");
}

TEST(EmitCApi, ThePrefixIsTheNameUnlessACNameItFormsIsReserved) {
  const System sys = quadruped();
  EXPECT_EQ(cPrefix(makePlan(sys, "quadruped", ScalarType::Double)), "quadruped");
  EXPECT_EQ(cPrefix(makePlan(sys, "torso", ScalarType::Double)), "torso");  // "to" + letter: only potentially reserved
  // M_NQ is of <math.h>'s M_ family, SIG_NQ of <signal.h>'s, INT_NQ of <stdint.h>'s.
  for (const char* name : {"M", "SIG", "INT", "LC", "FE"}) {
    ASSERT_EQ(makePlan(sys, name, ScalarType::Double).name, name) << "the C++ namespace itself is free";
    EXPECT_EQ(cPrefix(makePlan(sys, name, ScalarType::Double)), std::string("kw_") + name);
  }
}

TEST(EmitCApi, FloatSolversTakeFloatAndTheHeaderHoldsWhatTheSolverHolds) {
  System sys = quadruped();
  sys.functions = parseFunctionList("prox_pv,mass_matrix", "test", "functions");
  const SolverFiles f = generateSystem(sys, "M", ScalarType::Float, SolverInputs{});
  EXPECT_EQ(f.cHeaderName, "M_c.h");
  EXPECT_EQ(f.cSourceName, "M_c.cpp");
  EXPECT_NE(f.cHeader.find("void kw_M_prox_pv(const float* q, const float* v, const float* tau, float mu, int iterations,"),
            std::string::npos);
  EXPECT_NE(f.cHeader.find("void kw_M_mass_matrix(const float* q, void* work, float* M)"), std::string::npos);
  EXPECT_NE(f.cHeader.find("float kw_M_residual(const void* work)"), std::string::npos);
  EXPECT_NE(f.cHeader.find("#define kw_M_WORK_ALIGN 4"), std::string::npos);
  EXPECT_EQ(f.cHeader.find("constrained_aba("), std::string::npos);  // not held: not declared
  EXPECT_EQ(f.cHeader.find("inverse_dynamics("), std::string::npos);
  EXPECT_NE(f.cSource.find("M::prox_pv(q, v, tau, s, w, qdd, lambda);"), std::string::npos);
  EXPECT_NE(f.cSource.find("#include \"M.hpp\""), std::string::npos);
}

}  // namespace
}  // namespace proxgen::emit

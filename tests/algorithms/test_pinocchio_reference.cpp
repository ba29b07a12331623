// Conventions check against Pinocchio 3.7 (shared/models/reference): the same
// states must give the same qdd and multipliers. These numbers come from another
// library, so they test our conventions (joint order, free-flyer layout, frames,
// gravity, mu, multiplier sign), not only our internal consistency.
#include <fstream>
#include <nlohmann/json.hpp>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/prox_pv.hpp"
#include "model/state.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using nlohmann::json;

void checkReference(const std::string& caseName) {
  const json ref = json::parse(std::ifstream(test::modelPath("reference/" + caseName + ".json")));
  const Case* found = nullptr;
  const std::vector<Case> cases = test::sharedCases();
  for (const Case& c : cases)
    if (c.name == caseName) found = &c;
  ASSERT_NE(found, nullptr);
  const System sys = loadCaseSystem(*found);
  Data d(sys);
  const double mu = ref.at("project_mu").get<double>();
  ASSERT_EQ(sys.model.nq, ref.at("nq").get<int>());
  ASSERT_EQ(sys.nc, ref.at("constraint_rows").get<int>());
  for (const json& s : ref.at("samples")) {
    const State st = stateFromJson(sys.model, {{"q", s["q"]}, {"v", s["v"]}, {"tau", s["tau"]}}, caseName);
    const auto qddOf = [&](const char* key) { return velocityFromJson(sys.model, s.at(key), caseName, false); };
    // Pinocchio's lambda is the force on the robot; ours (docs/design.md, "Conventions") is its negative.
    VecX lamRef(sys.nc);
    for (const Constraint& c : sys.constraints)
      for (int r = 0; r < c.rows(); ++r) lamRef[c.row + r] = -s.at("lambda_k3").at(c.name)[r].get<double>();
    VecX lamConv(sys.nc);
    for (const Constraint& c : sys.constraints)
      for (int r = 0; r < c.rows(); ++r) lamConv[c.row + r] = -s.at("lambda_converged").at(c.name)[r].get<double>();

    // Two implementations in double, the same algorithm family: round-off of
    // cond * eps with cond ~ 1e4 (mu) on these models -> 1e-9 relative is a
    // conservative bound; the free motion has no penalty, hence 1e-11.
    EXPECT_LT(test::relErr(aba(sys, d, st.q, st.v, st.tau), qddOf("qdd_free")), 1e-11) << caseName;
    const char* keys[] = {"qdd_k1", "qdd_k2", "qdd_k3"};
    for (int K = 1; K <= 3; ++K) {
      constrainedAba(sys, d, st.q, st.v, st.tau, mu, K);
      EXPECT_LT(test::relErr(d.qdd, qddOf(keys[K - 1])), 1e-9) << caseName << " cABA K=" << K;
      proxPv(sys, d, st.q, st.v, st.tau, mu, K);
      EXPECT_LT(test::relErr(d.qdd, qddOf(keys[K - 1])), 1e-9) << caseName << " PV K=" << K;
      if (K == 3) {
        EXPECT_LT(test::relErr(d.lambda, lamRef), 1e-9) << caseName << " PV lambda";
      }
    }
    constrainedAba(sys, d, st.q, st.v, st.tau, mu, 200);
    EXPECT_LT(test::relErr(d.qdd, qddOf("qdd_converged")), 1e-9) << caseName << " cABA converged";
    EXPECT_LT(test::relErr(d.lambda, lamConv), 1e-9) << caseName << " cABA lambda converged";
  }
}

TEST(PinocchioReference, Solo_F3x2) {
  PROXGEN_REQUIRE_MODELS();
  checkReference("solo_f3x2");
}

TEST(PinocchioReference, Iiwa_H6) {
  PROXGEN_REQUIRE_MODELS();
  checkReference("iiwa_h6");
}

}  // namespace
}  // namespace proxgen

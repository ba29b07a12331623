// The strongest cross-check (docs/algorithms.md §3): from lambda = 0 with the same
// mu, after K multiplier updates constrainedABA, proxPV, proxLTL, proxLTLs and
// the dense proximal iteration return the same qdd^K and lambda^K, converged
// or not. On all nine cases of cases.yaml, at random states, for a small mu
// (100: one iteration more or less is far above round-off) and a large one (1e4).
//
// Tolerances: the round-off bounds of numerics.hpp (c n eps kappa with the
// Jacobi-scaled condition of the matrix each algorithm eliminates; dual
// algorithms see M and G, primal ones M + mu J^T J).
#include <cstdio>
#include <iostream>
#include <map>

#include "algorithms/dense_reference.hpp"
#include "algorithms/rnea.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::Bounds;
using test::kC;
using test::kEps;
const double kMus[] = {100.0, 1e4};

using test::kAlgorithms;
using test::Algorithm;

/// max_i |RNEA(q, v, qdd) + J^T lambda - tau|_i, and the size of the terms it is
/// made of: a backward-stable solve leaves a residual ~ n eps |A| |x| (no
/// condition number), so the bound is c n eps max_i (|tau| + |h| + |M||qdd| +
/// |J|^T|lambda|), plus for the primal algorithms the penalty terms they solve
/// with, mu |J|^T (|J||qdd| + |gamma| + |aStar|).
struct Identity {
  double residual, scale;
};

Identity dynamicsIdentity(const System& sys, const DenseProblem& p, const VecX& q, const VecX& v, const VecX& qdd,
                          const VecX& lambda, double mu, bool primal) {
  Data d(sys);
  const VecX res = rnea(sys, d, q, v, qdd) + p.J.transpose() * lambda - p.tau;
  const MatX Ja = p.J.cwiseAbs();
  VecX s = p.tau.cwiseAbs() + p.h.cwiseAbs() + p.M.cwiseAbs() * qdd.cwiseAbs() + Ja.transpose() * lambda.cwiseAbs();
  if (primal) s += mu * Ja.transpose() * (Ja * qdd.cwiseAbs() + p.gamma.cwiseAbs() + p.aStar.cwiseAbs());
  return {res.cwiseAbs().maxCoeff(), s.maxCoeff()};
}

/// The table for the issue note: largest disagreement with the dense iteration
/// per case, mu and algorithm (qdd and lambda, relErr), printed at the end.
struct Row {
  double qdd = 0, lambda = 0, ratio = 0;  // ratio: largest error / its bound
};
std::map<std::string, std::map<std::string, Row>>& table() {
  static std::map<std::string, std::map<std::string, Row>> t;
  return t;
}

class TablePrinter : public ::testing::Environment {
 public:
  void TearDown() override {
    if (table().empty()) return;
    std::cout << "\nLargest relErr vs the dense iteration (qdd / lambda), over states and K = 1, 2, 3, converged:\n";
    std::cout << "| case | mu | cABA | proxPV | proxLTL | proxLTLs | dense vs exact (converged) | largest error/bound |\n";
    std::cout << "|---|---|---|---|---|---|---|---|\n";
    for (const auto& [key, row] : table()) {
      std::cout << "| " << key;
      double ratio = 0;
      for (const char* a : {"cABA", "proxPV", "proxLTL", "proxLTLs", "exact"}) {
        char buf[64];
        std::snprintf(buf, sizeof buf, " | %.1e / %.1e", row.at(a).qdd, row.at(a).lambda);
        std::cout << buf;
        ratio = std::max(ratio, row.at(a).ratio);
      }
      char buf[32];
      std::snprintf(buf, sizeof buf, " | %.1e |\n", ratio);
      std::cout << buf;
    }
  }
};
const auto* const kPrinter = ::testing::AddGlobalTestEnvironment(new TablePrinter);

void record(const std::string& key, const std::string& alg, double eq, double el, double bound) {
  Row& r = table()[key][alg];
  r.qdd = std::max(r.qdd, eq);
  r.lambda = std::max(r.lambda, el);
  r.ratio = std::max(r.ratio, std::max(eq, el) / bound);
}

class Equivalence : public ::testing::TestWithParam<std::string> {};

TEST_P(Equivalence, AllAlgorithmsAgreeWithTheDenseIteration) {
  PROXGEN_REQUIRE_MODELS();
  const std::string name = GetParam();
  const Case* found = nullptr;
  const std::vector<Case> cases = test::sharedCases();
  for (const Case& c : cases)
    if (c.name == name) found = &c;
  ASSERT_NE(found, nullptr) << name << " is not in cases.yaml";
  const System sys = loadCaseSystem(*found);
  Data d(sys);
  std::mt19937 rng(std::hash<std::string>{}(name) & 0xffff);
  constexpr int kStates = 3;

  for (int st = 0; st < kStates; ++st) {
    const test::RandomState s = test::randomState(sys.model, rng);
    const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
    for (double mu : kMus) {
      const Bounds tol = test::roundoffBounds(p, mu);
      const std::string where = name + " state " + std::to_string(st) + " mu " + std::to_string(int(mu));
      char key[64];
      std::snprintf(key, sizeof key, "%s | %.0e", name.c_str(), mu);

      const int Kconv = test::convergedIterations(p, mu, tol.dual);
      ASSERT_GT(Kconv, 0) << where << ": the dense iteration did not settle in qdd";

      // At the small mu an iteration more or less must be visible above the
      // tolerance, otherwise this test could not catch a wrong iteration count.
      VecX q1, l1, q2, l2;
      denseProx(p, mu, 1, q1, l1);
      denseProx(p, mu, 2, q2, l2);
      if (mu == kMus[0]) {
        EXPECT_GT(test::relErr(q1, q2), 100 * tol.primal) << where;
      }

      std::map<std::string, double> lastResidual;
      for (int K : {1, 2, 3, Kconv}) {
        VecX qRef, lRef;
        denseProx(p, mu, K, qRef, lRef);
        for (const Algorithm& a : kAlgorithms) {
          a.run(sys, d, s.q, s.v, s.tau, mu, K);
          const double bound = a.primal ? tol.primal : tol.dual;
          const double eq = test::relErr(d.qdd, qRef), el = test::relErr(d.lambda, lRef);
          EXPECT_LE(eq, bound) << where << " " << a.name << " K=" << K << " qdd";
          EXPECT_LE(el, bound) << where << " " << a.name << " K=" << K << " lambda";
          record(key, a.name, eq, el, bound);

          const Identity id = dynamicsIdentity(sys, p, s.q, s.v, d.qdd, d.lambda, mu, a.primal);
          EXPECT_LE(id.residual, kC * sys.model.nv * kEps * id.scale)
              << where << " " << a.name << " K=" << K << ": RNEA(qdd) + J^T lambda != tau";

          // The residual r^K = y - G lambda^K has components y_j / (1 + mu g_j)^K
          // in G's eigenbasis: it falls strictly with K until it reaches the
          // round-off floor of the algorithm's qdd, bound * |J| |qdd|.
          const VecX qdd = d.qdd;
          const double r = (p.J * qdd + p.gamma - p.aStar).norm();
          const double floor = bound * (p.J.cwiseAbs() * qdd.cwiseAbs()).norm();
          if (lastResidual.count(a.name)) {
            EXPECT_TRUE(r < lastResidual[a.name] || r <= floor)
                << where << " " << a.name << " K=" << K << ": residual " << r << " did not fall from "
                << lastResidual[a.name];
          }
          lastResidual[a.name] = r;
        }
      }
      // Converged: the least-squares answer (here J has full row rank, so the KKT one).
      VecX qConv, lConv, qEx, lEx;
      denseProx(p, mu, Kconv, qConv, lConv);
      denseExact(p, qEx, lEx);
      EXPECT_LE(test::relErr(qConv, qEx), tol.dual) << where << " converged qdd vs denseExact";
      record(key, "exact", test::relErr(qConv, qEx), test::relErr(lConv, lEx), tol.dual);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, Equivalence,
                         ::testing::Values("iiwa_h3", "iiwa_h6", "solo_f3x2", "solo_f3x4", "talos_f6x2",
                                           "talos_f6x2_h6x2", "atlas_shadow_f6x2", "atlas_shadow_f6x2_t3x5",
                                           "atlas_shadow_f6x2_t3x10"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// K = 0 is the free motion with lambda = 0 for every algorithm.
TEST(Equivalence, ZeroIterationsGiveTheFreeMotion) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys);
    std::mt19937 rng(7);
    const test::RandomState s = test::randomState(sys.model, rng);
    const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
    VecX qRef, lRef;
    denseProx(p, 1e4, 0, qRef, lRef);
    const Bounds tol = test::roundoffBounds(p, 1e4);
    for (const Algorithm& a : kAlgorithms) {
      a.run(sys, d, s.q, s.v, s.tau, 1e4, 0);
      EXPECT_EQ(d.lambda.cwiseAbs().maxCoeff(), 0.0) << c.name << " " << a.name;
      // No penalty enters at K = 0: only M's conditioning matters (the dual bound covers it).
      EXPECT_LE(test::relErr(d.qdd, qRef), tol.dual) << c.name << " " << a.name;
    }
  }
}

}  // namespace
}  // namespace proxgen

// Redundant and singular layouts are normal (docs/algorithms.md §2): every algorithm
// stays finite and its qdd converges to the least-squares answer (denseExact:
// minimum-norm multipliers G^+ y). When the rows are inconsistent the
// multipliers grow with K while qdd has settled; when they are consistent the
// multipliers converge too.
//
// Tolerance: the round-off bounds of numerics.hpp (G's condition on its range)
// plus one term the regular cases hardly see: the multipliers can be large
// (they grow like K mu |y| along null(G) for inconsistent rows), and
// qdd = qdd_free - M^-1 J^T lambda is formed from them (multiplierRoundoff).
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kAlgorithms;
using test::kC;
using test::kEps;

std::string dataPath(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/analytic/" + file; }

double maxAbs(const VecX& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

/// Rank of G by the rule denseExact uses (numerics.hpp, scaledCondition).
int delassusRank(const DenseProblem& p) {
  const MatX G = p.J * p.M.llt().solve(p.J.transpose());
  const VecX ev = Eigen::SelfAdjointEigenSolver<MatX>(G, Eigen::EigenvaluesOnly).eigenvalues();
  int r = 0;
  for (double e : ev) r += e > double(G.rows()) * kEps * ev.maxCoeff();
  return r;
}

/// Runs every algorithm at the K where the dense iteration has settled and at
/// a much larger K, and checks qdd against denseExact. `consistent` says
/// whether the multipliers must converge (true) or grow (false).
void checkLeastSquares(const System& sys, const VecX& q, const VecX& v, const VecX& tau, bool consistent,
                       const std::string& what) {
  const DenseProblem p = assembleDense(sys, q, v, tau);
  ASSERT_LT(delassusRank(p), sys.nc) << what << ": the layout is meant to be singular here";
  VecX qEx, lEx;
  denseExact(p, qEx, lEx);
  ASSERT_TRUE(qEx.allFinite() && lEx.allFinite()) << what;
  // Size of the row accelerations y = J qdd_free + gamma - aStar: their
  // round-off c n eps |y| is what the iteration integrates along null(G).
  const VecX qddFree = p.M.llt().solve(p.tau - p.h);
  const double ySize = maxAbs(p.J.cwiseAbs() * qddFree.cwiseAbs() + p.gamma.cwiseAbs() + p.aStar.cwiseAbs());
  Data d(sys);
  double worst = 0;  // largest qdd error / tolerance, recorded for the report
  for (double mu : {100.0, 1e4}) {
    const test::Bounds b = test::roundoffBounds(p, mu);
    const int Kconv = test::convergedIterations(p, mu, b.dual);
    ASSERT_GT(Kconv, 0) << what << " mu " << mu << ": the dense iteration did not settle in qdd";
    for (const test::Algorithm& a : kAlgorithms) {
      double lastNorm = 0;
      VecX lastLambda;
      for (int K : {Kconv, 10 * Kconv}) {
        a.run(sys, d, q, v, tau, mu, K);
        const std::string where = what + " " + a.name + " mu " + std::to_string(int(mu)) + " K " + std::to_string(K);
        ASSERT_TRUE(d.qdd.allFinite() && d.lambda.allFinite()) << where;
        const double tol =
            (a.primal ? b.primal : b.dual) + test::multiplierRoundoff(p, d.lambda) / std::max(1.0, maxAbs(qEx));
        EXPECT_LE(test::relErr(d.qdd, qEx), tol) << where;
        worst = std::max(worst, test::relErr(d.qdd, qEx) / tol);
        if (K != Kconv) {
          if (consistent) {
            // Along range(G) the multipliers converge like qdd does; along
            // null(G) they integrate the round-off of y, mu c n eps |y| per
            // iteration, over the K iterations run.
            const double drift = K * mu * kC * sys.model.nv * kEps * ySize / std::max(1.0, maxAbs(lastLambda));
            EXPECT_LE(test::relErr(d.lambda, lastLambda), tol + drift) << where << ": lambda did not converge";
          } else {
            // Along null(G): lambda^K ~ K mu y_null, so 10x the iterations ~ 10x the norm.
            EXPECT_GT(d.lambda.norm(), 5 * lastNorm) << where << ": lambda was expected to grow";
          }
        }
        lastNorm = d.lambda.norm();
        lastLambda = d.lambda;
      }
    }
  }
  ::testing::Test::RecordProperty(what + " worst qdd err/tol", std::to_string(worst));
}

/// A free-flyer state with a tilted base; the other joints from `rng`.
test::RandomState tiltedState(const Model& m, std::mt19937& rng) {
  test::RandomState s = test::randomState(m, rng);
  s.q.head<7>() << 0.1, -0.2, 0.3, Eigen::Quaterniond(0.8, 0.3, -0.4, 0.35).normalized().coeffs();
  return s;
}

// Two 6D welds on one link: 12 rows of rank 6. Consistent (both say "this
// rigid body does not accelerate"), so lambda converges too, to the minimum-norm split.
TEST(Singular, TwoWeldsOnOneLink) {
  const System sys = loadSystem(dataPath("floating_arm.urdf"), dataPath("floating_arm_two_welds.yaml"));
  std::mt19937 rng(31);
  for (int st = 0; st < 3; ++st) {
    const test::RandomState s = tiltedState(sys.model, rng);
    checkLeastSquares(sys, s.q, s.v, s.tau, true, "two welds state " + std::to_string(st));
  }
}

// Four coplanar point contacts on a rigid box: 12 rows of rank 6. Without
// rotation (w = 0) they agree (the box can stay put). With w != 0 they cannot:
// a corner's classical acceleration is a_o + alpha x r + w x (w x r), and no
// skew map alpha x . cancels the symmetric w w^T - |w|^2 I on the corners'
// plane, so the rows are inconsistent: lambda grows, qdd settles.
TEST(Singular, FourCoplanarContacts) {
  const System sys = loadSystem(dataPath("box.urdf"), dataPath("box_4_corners.yaml"));
  VecX q(7), tau(6), v(6);
  q << 0.1, -0.2, 0.3, Eigen::Quaterniond(0.95, 0.1, -0.2, 0.05).normalized().coeffs();
  tau << 0.3, -0.2, 0.5, 0.05, -0.02, 0.01;
  v << 0.4, -0.3, 0.2, 0, 0, 0;
  checkLeastSquares(sys, q, v, tau, true, "box, no rotation");
  v << 0.4, -0.3, 0.2, 0.8, -0.5, 1.2;
  checkLeastSquares(sys, q, v, tau, false, "box, rotating");
}

// A 6D weld on the fully stretched iiwa (q = 0): rank 3 of 6 (README of the
// shared models). With a non-zero velocity the rows are inconsistent: lambda
// grows, qdd must settle.
TEST(Singular, WeldOnStretchedArm) {
  PROXGEN_REQUIRE_MODELS();
  // A renamed case must fail the test, not skip its only check.
  const std::vector<Case> cases = test::sharedCases();
  const Case* found = nullptr;
  for (const Case& c : cases)
    if (c.name == "iiwa_h6") found = &c;
  ASSERT_NE(found, nullptr) << "iiwa_h6 is not in cases.yaml";
  const System sys = loadCaseSystem(*found);
  std::mt19937 rng(33);
  const test::RandomState s = test::randomState(sys.model, rng);
  const VecX q = VecX::Zero(sys.model.nq);
  checkLeastSquares(sys, q, s.v, s.tau, false, "stretched iiwa");
}

}  // namespace
}  // namespace proxgen

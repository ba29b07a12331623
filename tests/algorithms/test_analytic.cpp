// Closed-form answers on small hand-written systems (tests/data/analytic): the
// bottom of the verification pyramid. Nothing here is compared with another
// implementation of the same algorithm; the expected values are physics.
#include "algorithms/aba.hpp"
#include "algorithms/kinematics.hpp"
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kAlgorithms;
using test::kEps;

std::string dataPath(const std::string& file) { return std::string(PROXGEN_TEST_DATA_DIR) + "/analytic/" + file; }

System withLayout(const std::string& urdf, const std::string& layout) {
  return loadSystem(dataPath(urdf), dataPath(layout));
}

/// A free-flyer configuration from a position and an orientation.
VecX freeFlyerQ(const Vec3& p, const Eigen::Quaterniond& R) {
  VecX q(7);
  q << p, R.normalized().coeffs();
  return q;
}

const Eigen::Quaterniond kTilted = Eigen::Quaterniond(0.8, 0.3, -0.4, 0.35).normalized();

double maxAbs(const VecX& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

// ---------------------------------------------------------------------------
// Free motion.

// At rest, a free body (any inertia, COM anywhere) under gravity only has
// zero angular acceleration (gravity has no moment about the COM and w = 0),
// so the COM and the body origin accelerate alike: p'' = g, i.e.
// qdd = [R^T g; 0] in the body frame.
TEST(Analytic, FreeBodyAtRestFallsWithGravity) {
  const System sys = loadSystemWithoutLayout(dataPath("free_body.urdf"), true);
  Data d(sys);
  const VecX q = freeFlyerQ({0.1, -0.2, 0.3}, kTilted), v = VecX::Zero(6), tau = VecX::Zero(6);
  const Mat3 R = kTilted.normalized().toRotationMatrix();
  const VecX expected = stack(R.transpose() * sys.model.gravity, Vec3::Zero());
  const DenseProblem p = assembleDense(sys, q, v, tau);
  // One 6 x 6 solve with M: c n eps kappa_s(M) (numerics.hpp).
  const double tol = test::roundoffBounds(p, 1.0).dual;
  EXPECT_LE(test::relErr(aba(sys, d, q, v, tau), expected), tol);
  VecX qdd, lambda;
  denseExact(p, qdd, lambda);
  EXPECT_LE(test::relErr(qdd, expected), tol);
  for (const test::Algorithm& a : kAlgorithms) {
    a.run(sys, d, q, v, tau, 1e4, 3);  // no constraint rows: the iterations change nothing
    EXPECT_LE(test::relErr(d.qdd, expected), tol) << a.name;
  }
}

// A tumbling body whose COM is its origin. v = R^T p' (the origin's velocity in
// the body frame) and R' = R [w], so
//   d/dt v = R^T p'' + (R^T)' p' = R^T p'' - [w] R^T p' = R^T g - w x v,
// since the COM (= origin) falls with p'' = g. The angular part is Euler's
// equation about the COM in body coordinates, I w' + w x I w = 0.
TEST(Analytic, SpinningBodyFallsAndTumbles) {
  const System sys = loadSystemWithoutLayout(dataPath("spinning_body.urdf"), true);
  Data d(sys);
  const VecX q = freeFlyerQ({0.0, 0.5, 1.0}, kTilted), tau = VecX::Zero(6);
  VecX v(6);
  v << 0.7, -1.2, 0.4, 2.0, -1.5, 3.0;
  const Vec3 vl = v.head<3>(), w = v.tail<3>();
  const Mat3 R = kTilted.normalized().toRotationMatrix();
  const Mat3 I = sys.model.bodies[1].inertia.Ic;
  const VecX expected = stack(R.transpose() * sys.model.gravity - w.cross(vl), -I.inverse() * w.cross(I * w));
  const DenseProblem p = assembleDense(sys, q, v, tau);
  const double tol = test::roundoffBounds(p, 1.0).dual;
  EXPECT_LE(test::relErr(aba(sys, d, q, v, tau), expected), tol);
  VecX qdd, lambda;
  denseExact(p, qdd, lambda);
  EXPECT_LE(test::relErr(qdd, expected), tol);
  for (const test::Algorithm& a : kAlgorithms) {
    a.run(sys, d, q, v, tau, 1e4, 0);
    EXPECT_LE(test::relErr(d.qdd, expected), tol) << a.name;
  }
}

// Point mass m at distance l on a hinge about y: the bob sits at
// (-l sin th, 0, -l cos th), gravity's moment about y is -m g l sin th, and the
// inertia about the hinge is m l^2, so th'' = -(g/l) sin th + tau / (m l^2)
// whatever th' is (one dof: no Coriolis term).
TEST(Analytic, PendulumMatchesItsEquationOfMotion) {
  const System sys = loadSystemWithoutLayout(dataPath("pendulum.urdf"), false);
  Data d(sys);
  const double m = 1.3, l = 0.7, g = 9.81;
  ASSERT_EQ(sys.model.nv, 1);
  ASSERT_DOUBLE_EQ(sys.model.gravity.z(), -g);
  for (double th : {0.0, 0.4, -1.3, 2.5})
    for (double thd : {0.0, 1.7})
      for (double t : {0.0, 0.9}) {
        const VecX q = VecX::Constant(1, th), v = VecX::Constant(1, thd), tau = VecX::Constant(1, t);
        const double expected = -(g / l) * std::sin(th) + t / (m * l * l);
        // A scalar division after sums of a few terms each of size ~ g / l or
        // tau / (m l^2): a few eps relative to the larger term.
        const double tol = 10 * kEps * (g / l + std::abs(t) / (m * l * l));
        EXPECT_NEAR(aba(sys, d, q, v, tau)[0], expected, tol) << "theta " << th;
        VecX qdd, lambda;
        denseExact(assembleDense(sys, q, v, tau), qdd, lambda);
        EXPECT_NEAR(qdd[0], expected, tol) << "theta " << th;
        for (const test::Algorithm& a : kAlgorithms) {
          a.run(sys, d, q, v, tau, 1e4, 0);
          EXPECT_NEAR(d.qdd[0], expected, tol) << a.name << " theta " << th;
        }
      }
}

// ---------------------------------------------------------------------------
// Constrained motion (converged: K found by the dense iteration settling in qdd).

/// Every algorithm at convergence and denseExact: (name, qdd) pairs.
std::vector<std::pair<std::string, VecX>> convergedAnswers(const System& sys, const DenseProblem& p, const VecX& q,
                                                           const VecX& v, const VecX& tau, double mu) {
  const int K = test::convergedIterations(p, mu, test::roundoffBounds(p, mu).dual);
  EXPECT_GT(K, 0) << "the dense iteration did not settle";
  std::vector<std::pair<std::string, VecX>> out;
  Data d(sys);
  for (const test::Algorithm& a : kAlgorithms) {
    a.run(sys, d, q, v, tau, mu, K);
    out.emplace_back(a.name, d.qdd);
  }
  VecX qdd, lambda;
  denseProx(p, mu, K, qdd, lambda);
  out.emplace_back("denseProx", qdd);
  denseExact(p, qdd, lambda);
  out.emplace_back("denseExact", qdd);
  return out;
}

/// The round-off bound of the algorithm named (primal or dual), times the
/// size of the accelerations the constraint forces cancel (qdd_free).
double convergedTolerance(const std::string& name, const DenseProblem& p, double mu) {
  const test::Bounds b = test::roundoffBounds(p, mu);
  const bool primal = name == "cABA" || name == "proxLTLs";
  const VecX qddFree = p.M.llt().solve(p.tau - p.h);
  return (primal ? b.primal : b.dual) * std::max(1.0, maxAbs(qddFree));
}

// Welded with zero velocity and no gains: the frame must not accelerate, and a
// free body has nothing else to move, so qdd = 0 exactly (J is invertible here:
// a 6D weld on a 6-dof body).
TEST(Analytic, WeldedBodyAtRestDoesNotAccelerate) {
  const System sys = withLayout("free_body.urdf", "free_body_weld.yaml");
  const VecX q = freeFlyerQ({0.1, -0.2, 0.3}, kTilted), v = VecX::Zero(6);
  VecX tau(6);
  tau << 1.0, -2.0, 0.5, 0.3, -0.2, 0.1;
  const DenseProblem p = assembleDense(sys, q, v, tau);
  for (double mu : {100.0, 1e4})
    for (const auto& [name, qdd] : convergedAnswers(sys, p, q, v, tau, mu))
      EXPECT_LE(maxAbs(qdd), convergedTolerance(name, p, mu)) << name << " mu " << mu;
}

// Finite differences of a point's world velocity along (q "+" t v, v + t qdd):
// central, h = 1e-5 ~ eps^(1/3) (truncation h^2/6 |p'''| against round-off
// eps |p'| / h). A point at distance r from the origin of a body turning at
// Omega = 1 + |v|_1 with accelerations A = max |qdd| has |p'''| <~ (1 + Omega)^2
// ((1 + Omega)(1 + r) + A); factor 10 of margin (order-one constants).
constexpr double kH = 1e-5;

Vec3 worldPointVelocity(const Data& d, const Constraint& c) {
  return framePlacement(d, c.body, c.placement).R * frameVelocity(d, c.body, c.placement).head<3>();
}

Vec3 pointAccelerationFd(const System& sys, const Constraint& c, const VecX& q, const VecX& v, const VecX& qdd) {
  Data dp(sys), dm(sys);
  forwardKinematics(sys, dp, test::integrate(sys.model, q, kH * v), v + kH * qdd);
  forwardKinematics(sys, dm, test::integrate(sys.model, q, -kH * v), v - kH * qdd);
  return (worldPointVelocity(dp, c) - worldPointVelocity(dm, c)) / (2 * kH);
}

double fdTolerance(const VecX& v, const VecX& qdd, const Constraint& c) {
  const double Omega = 1 + v.cwiseAbs().sum(), r = c.placement.p.norm();
  return 10 * (kH * kH / 6 + kEps / kH) * (1 + Omega) * (1 + Omega) * ((1 + Omega) * (1 + r) + maxAbs(qdd));
}

// A point contact on a spinning body: J qdd + gamma = 0 must hold the point's
// CLASSICAL acceleration (what a world observer measures) at zero, which needs
// the drift w_C x v_C in gamma (docs/algorithms.md §2). Checked by finite
// differences of the point's world velocity, for every algorithm; then the same
// solve with the drift dropped is shown to miss by exactly that drift.
TEST(Analytic, PointContactHoldsClassicalAccelerationOnlyWithDrift) {
  const System sys = withLayout("free_body.urdf", "free_body_point.yaml");
  const Constraint& c = sys.constraints[0];
  const VecX q = freeFlyerQ({0.1, -0.2, 0.3}, kTilted);
  VecX v(6), tau(6);
  v << 0.5, -0.3, 0.8, 1.5, -2.0, 1.0;
  tau << 0.2, 0.1, -0.3, 0.05, 0.0, -0.1;
  const DenseProblem p = assembleDense(sys, q, v, tau);
  const double mu = 1e4;
  for (const auto& [name, qdd] : convergedAnswers(sys, p, q, v, tau, mu)) {
    const Vec3 acc = pointAccelerationFd(sys, c, q, v, qdd);
    // FD error plus the solver's own round-off on the accelerations (times the lever arm ~1).
    const double tol = fdTolerance(v, qdd, c) + convergedTolerance(name, p, mu);
    EXPECT_LE(acc.cwiseAbs().maxCoeff(), tol) << name;
  }

  // Without the drift the solve holds a_lin (the C-frame derivative of v_C) at
  // zero instead, so the classical acceleration is left at R_C (w_C x v_C).
  Data d(sys);
  forwardKinematics(sys, d, q, v);
  const Vec6 vC = frameVelocity(d, c.body, c.placement);
  const Vec3 drift = vC.tail<3>().cross(vC.head<3>());
  DenseProblem noDrift = p;
  noDrift.gamma.segment<3>(c.row) -= drift;
  VecX qdd, lambda;
  denseExact(noDrift, qdd, lambda);
  const Vec3 acc = pointAccelerationFd(sys, c, q, v, qdd);
  const double tol = fdTolerance(v, qdd, c) + convergedTolerance("denseExact", p, mu);
  const Vec3 expectedMiss = framePlacement(d, c.body, c.placement).R * drift;
  EXPECT_LE((acc - expectedMiss).cwiseAbs().maxCoeff(), tol);
  EXPECT_GT(acc.norm(), 1e4 * tol) << "the drift must matter in this state, otherwise the test shows nothing";
}

// ---------------------------------------------------------------------------
// Baumgarte gains: a_star = -kd (constraint velocity) - kp (placement error).

// 6D: the spatial acceleration of C in C is a_C = -kd V_C - kp xi with
// xi = log6(T*^-1 T_C). Checked without any log: recover xi from the answer and
// compare exp6(xi) with T*^-1 T_C. For a free body a_C = X_{C<-B} qdd (the
// free flyer has no velocity-product term: v x v = 0).
TEST(Analytic, BaumgarteWeldDrivesTheFrameTowardsItsTarget) {
  const System sys = withLayout("free_body.urdf", "free_body_weld_gains.yaml");
  const Constraint& c = sys.constraints[0];
  const VecX q = freeFlyerQ({0.1, -0.2, 0.3}, kTilted);
  VecX v(6), tau(6);
  v << 0.3, -0.6, 0.2, 0.9, 0.4, -0.7;
  tau << 0.2, 0.1, -0.3, 0.05, 0.0, -0.1;
  Data d(sys);
  forwardKinematics(sys, d, q, v);
  const Vec6 VC = frameVelocity(d, c.body, c.placement);
  const SE3 err = c.target.inverse() * framePlacement(d, c.body, c.placement);
  const DenseProblem p = assembleDense(sys, q, v, tau);
  for (double mu : {100.0, 1e4})
    for (const auto& [name, qdd] : convergedAnswers(sys, p, q, v, tau, mu)) {
      const Vec6 aC = c.placement.actInvMotion(qdd);
      const Vec6 xi = -(aC + c.kd * VC) / c.kp;
      const SE3 E = test::exp6(xi);
      // qdd's error (convergedTolerance) divided by kp gives xi's; exp6 has unit
      // derivative in rotation and (1 + |p|) in translation.
      const double tol = 10 * convergedTolerance(name, p, mu) / c.kp * (1 + err.p.norm());
      EXPECT_LE((E.R - err.R).cwiseAbs().maxCoeff(), tol) << name << " mu " << mu;
      EXPECT_LE((E.p - err.p).cwiseAbs().maxCoeff(), tol) << name << " mu " << mu;
    }
}

// 3D: the classical acceleration of the point, in C, is -kd v_C - kp R_C^T (p_C - p*).
TEST(Analytic, BaumgartePointDrivesThePointTowardsItsTarget) {
  const System sys = withLayout("free_body.urdf", "free_body_point_gains.yaml");
  const Constraint& c = sys.constraints[0];
  const VecX q = freeFlyerQ({0.1, -0.2, 0.3}, kTilted);
  VecX v(6), tau(6);
  v << 0.3, -0.6, 0.2, 0.9, 0.4, -0.7;
  tau << 0.2, 0.1, -0.3, 0.05, 0.0, -0.1;
  Data d(sys);
  forwardKinematics(sys, d, q, v);
  const SE3 oMc = framePlacement(d, c.body, c.placement);
  const Vec3 vC = frameVelocity(d, c.body, c.placement).head<3>();
  const Vec3 expected = -c.kd * vC - c.kp * (oMc.R.transpose() * (oMc.p - c.target.p));
  const DenseProblem p = assembleDense(sys, q, v, tau);
  const double mu = 1e4;
  for (const auto& [name, qdd] : convergedAnswers(sys, p, q, v, tau, mu)) {
    const Vec3 acc = oMc.R.transpose() * pointAccelerationFd(sys, c, q, v, qdd);
    const double tol = fdTolerance(v, qdd, c) + convergedTolerance(name, p, mu);
    EXPECT_LE((acc - expected).cwiseAbs().maxCoeff(), tol) << name;
  }
}

// Gains on a multi-body system (floating torso welded, arm tip in contact):
// every algorithm follows the dense iteration at K = 1, 2, 3 and converged.
TEST(Analytic, BaumgarteGainsAgreeWithTheDenseReference) {
  const System sys = withLayout("floating_arm.urdf", "floating_arm_gains.yaml");
  Data d(sys);
  std::mt19937 rng(21);
  for (int st = 0; st < 3; ++st) {
    const test::RandomState s = test::randomState(sys.model, rng);
    const DenseProblem p = assembleDense(sys, s.q, s.v, s.tau);
    ASSERT_GT(p.aStar.norm(), 1.0) << "the gains must produce a target in this state";
    for (double mu : {100.0, 1e4}) {
      const test::Bounds b = test::roundoffBounds(p, mu);
      const int Kconv = test::convergedIterations(p, mu, b.dual);
      ASSERT_GT(Kconv, 0);
      for (int K : {1, 2, 3, Kconv}) {
        VecX qRef, lRef;
        denseProx(p, mu, K, qRef, lRef);
        for (const test::Algorithm& a : kAlgorithms) {
          a.run(sys, d, s.q, s.v, s.tau, mu, K);
          const double tol = a.primal ? b.primal : b.dual;
          EXPECT_LE(test::relErr(d.qdd, qRef), tol) << a.name << " K=" << K << " mu " << mu;
          EXPECT_LE(test::relErr(d.lambda, lRef), tol) << a.name << " K=" << K << " mu " << mu;
        }
      }
      VecX qConv, lConv, qEx, lEx;
      denseProx(p, mu, Kconv, qConv, lConv);
      denseExact(p, qEx, lEx);
      EXPECT_LE(test::relErr(qConv, qEx), b.dual) << "mu " << mu;
      // Converged, the rows meet their targets: J qdd + gamma = aStar.
      EXPECT_LE(test::relErr(p.J * qEx + p.gamma, p.aStar), b.dual) << "mu " << mu;
    }
  }
}

}  // namespace
}  // namespace proxgen

// Identities the building blocks must satisfy on every shared model (iiwa
// fixed, solo / talos / atlas floating) at random states: ABA inverts RNEA,
// CRBA's M is symmetric positive definite and M qdd + h = RNEA, frame
// Jacobians are the derivatives of frame placements, and J qdd + gamma is the
// derivative of the constraint velocities. The derivatives are checked against
// central finite differences, so these tests do not trust any of the
// kinematics they check.
//
// Finite differences: central, step h = 1e-5 ~ eps^(1/3), which balances the
// truncation error h^2/6 |f'''| against the round-off eps |f| / h. Scales:
//  - placements under a unit joint speed: |f'''| <= reach (a point at distance
//    r from an axis: d^3/dt^3 of R(t) r has size r; for the free flyer the
//    perturbation is exp(t xi), same bound), so the error is
//    (h^2/6 + eps/h) * reach, with reach = 1 + the largest frame distance from
//    the world origin;
//  - velocities along (q(t), v + t qdd): each derivative brings a factor of at
//    most Omega = 1 + sum |v| (the fastest any frame can turn), so the relative
//    error is h^2/6 Omega^2 + eps/h.
// Both get a factor 10 of margin (the constants in these bounds are of order one).
#include "algorithms/aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/joint_space.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kEps;
constexpr double kH = 1e-5;
constexpr int kStates = 3;

struct SharedModel {
  const char* file;
  bool floating;
};
const SharedModel kModels[] = {
    {"iiwa14.urdf", false}, {"solo12.urdf", true}, {"talos.urdf", true}, {"atlas_shadow.urdf", true}};

using test::integrate;
using test::vee;

System modelSystem(const SharedModel& sm) { return loadSystemWithoutLayout(test::modelPath(sm.file), sm.floating); }

TEST(Identities, AbaInvertsRnea) {
  PROXGEN_REQUIRE_MODELS();
  for (const SharedModel& sm : kModels) {
    const System sys = modelSystem(sm);
    Data d(sys);
    std::mt19937 rng(11);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(sys.model, rng);
      const VecX qdd = s.tau;  // any acceleration in [-1, 1]
      const VecX tau = rnea(sys, d, s.q, s.v, qdd);
      const VecX back = aba(sys, d, s.q, s.v, tau);
      // ABA is Gaussian elimination on M (Featherstone): error c n eps kappa_s(M)
      // with the Jacobi-scaled condition (numerics.hpp), c = 10.
      const double kappa = test::scaledCondition(crba(sys, d, s.q));
      EXPECT_LE(test::relErr(back, qdd), 10 * sys.model.nv * kEps * kappa) << sm.file << " state " << st;
    }
  }
}

TEST(Identities, CrbaIsSymmetricPositiveDefiniteAndMatchesRnea) {
  PROXGEN_REQUIRE_MODELS();
  for (const SharedModel& sm : kModels) {
    const System sys = modelSystem(sm);
    Data d(sys);
    std::mt19937 rng(12);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(sys.model, rng);
      const int n = sys.model.nv;
      const MatX M = crba(sys, d, s.q);
      const double Mmax = M.cwiseAbs().maxCoeff();
      // A separately computed mirror block would differ by its round-off, n eps |M|.
      EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), n * kEps * Mmax) << sm.file;
      const VecX ev = Eigen::SelfAdjointEigenSolver<MatX>(M, Eigen::EigenvaluesOnly).eigenvalues();
      EXPECT_GT(ev.minCoeff(), 0.0) << sm.file << " M not positive definite";

      const VecX qdd = s.tau;
      const VecX h = nonLinearEffects(sys, d, s.q, s.v);
      const VecX tau = rnea(sys, d, s.q, s.v, qdd);
      // Two evaluations of the same sums in a different order: round-off
      // c n eps (|M||qdd| + |h| + |tau|), no condition number involved.
      const VecX scale = M.cwiseAbs() * qdd.cwiseAbs() + h.cwiseAbs() + tau.cwiseAbs();
      EXPECT_LE((M * qdd + h - tau).cwiseAbs().maxCoeff(), 10 * n * kEps * scale.maxCoeff()) << sm.file;
    }
  }
}

TEST(Identities, FrameJacobiansAreDerivativesOfPlacements) {
  PROXGEN_REQUIRE_MODELS();
  for (const SharedModel& sm : kModels) {
    const System sys = modelSystem(sm);
    const Model& m = sys.model;
    Data d0(sys), dp(sys), dm(sys);
    std::mt19937 rng(13);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(m, rng);
      forwardKinematics(sys, d0, s.q);
      double reach = 1;
      for (const Frame& f : m.frames) reach = std::max(reach, 1 + framePlacement(d0, f.body, f.placement).p.norm());
      const double tol = 10 * (kH * kH / 6 + kEps / kH) * reach;
      std::vector<MatX> J;
      for (const Frame& f : m.frames) J.push_back(frameJacobian(sys, d0, f.body, f.placement));
      double worst = 0;
      for (int k = 0; k < m.nv; ++k) {
        const VecX e = VecX::Unit(m.nv, k) * kH;
        forwardKinematics(sys, dp, integrate(m, s.q, e));
        forwardKinematics(sys, dm, integrate(m, s.q, -e));
        for (std::size_t fi = 0; fi < m.frames.size(); ++fi) {
          const Frame& f = m.frames[fi];
          const SE3 T0 = framePlacement(d0, f.body, f.placement);
          const SE3 Tp = framePlacement(dp, f.body, f.placement), Tm = framePlacement(dm, f.body, f.placement);
          // Local twist: origin velocity and angular velocity, both in the frame's coordinates.
          const Vec6 fd = stack(T0.R.transpose() * (Tp.p - Tm.p), vee(T0.R.transpose() * (Tp.R - Tm.R))) / (2 * kH);
          const double err = (fd - J[fi].col(k)).cwiseAbs().maxCoeff();
          worst = std::max(worst, err);
          EXPECT_LE(err, tol) << sm.file << " frame " << f.name << " column " << k;
        }
      }
      RecordProperty(std::string(sm.file) + "_state" + std::to_string(st) + "_jacobian_fd_err_over_tol",
                     std::to_string(worst / tol));
    }
  }
}

// The constraint rows: J qdd + gamma is the time derivative of the constraint
// velocity along q(t) = q "+" t v, v(t) = v + t qdd (the O(t^2) term of q(t)
// is even in t and cancels in the central difference). 6D: the twist of a
// body-fixed frame in its own coordinates, whose derivative is its spatial
// acceleration. 3D: the classical acceleration of the point: difference the
// WORLD-frame velocity of the point and rotate the result into C (differencing
// the C-frame velocity instead would lose w x v).
TEST(Identities, ConstraintRowsAreDerivativesOfConstraintVelocities) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    const Model& m = sys.model;
    Data d0(sys), dp(sys), dm(sys);
    std::mt19937 rng(14);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(m, rng);
      const VecX qdd = s.tau;
      constraintJacobian(sys, d0, s.q, s.v);
      const VecX rows = d0.J * qdd + d0.gamma;
      forwardKinematics(sys, dp, integrate(m, s.q, kH * s.v), s.v + kH * qdd);
      forwardKinematics(sys, dm, integrate(m, s.q, -kH * s.v), s.v - kH * qdd);
      const VecX fd = test::constraintRowsByDifferences(sys, d0, dp, dm, kH);
      const double Omega = 1 + s.v.cwiseAbs().sum();
      const double err = test::relErr(rows, fd), tol = 10 * (kH * kH / 6 * Omega * Omega + kEps / kH);
      EXPECT_LE(err, tol) << c.name << " state " << st;
      RecordProperty(c.name + "_state" + std::to_string(st) + "_rows_fd_err_over_tol", std::to_string(err / tol));
    }
  }
}

// The joint-space algorithms (proxLTL, proxLTLs) assemble J, gamma, aStar their
// own way (no allocation, from RNEA's bias accelerations); they must equal
// constraintJacobian's. Same quantities, different order of operations:
// round-off c n eps times their size, c = 10.
TEST(Identities, JointSpaceAssemblyMatchesConstraintJacobian) {
  PROXGEN_REQUIRE_MODELS();
  for (const Case& c : test::sharedCases()) {
    const System sys = loadCaseSystem(c);
    Data d(sys), ref(sys);
    std::mt19937 rng(15);
    const test::RandomState s = test::randomState(sys.model, rng);
    constraintJacobian(sys, ref, s.q, s.v);
    joint_space::assemble(sys, d, s.q, s.v);
    const double tol = 10 * sys.model.nv * kEps;
    EXPECT_LE(test::relErr(VecX(d.J.reshaped()), VecX(ref.J.reshaped())), tol) << c.name;
    EXPECT_LE(test::relErr(d.gamma, ref.gamma), tol) << c.name;
    EXPECT_LE(test::relErr(d.aStar, ref.aStar), tol) << c.name;
  }
}

}  // namespace
}  // namespace proxgen

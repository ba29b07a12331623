// constraintWrenches (algorithms/constraint_kinematics.hpp; issue 18 item 6):
// each constraint's wrench on the robot in world axes, force then torque about
// the constraint frame's origin, with the solvers' sign. Checked against two
// identities the function does not enter:
//  - mapped through each frame's world Jacobian (by central differences of the
//    placements alone: the point's world velocity and the frame's world angular
//    velocity per unit dq), the wrenches sum to the generalized constraint force
//    -J^T lambda (J: constraintJacobianRows, the solvers' rows). A wrong sign,
//    a missing rotation or a wrong reference point breaks it at a random state.
//  - a floating robot held still (v = 0) by torques that keep qdd = 0: its
//    contact wrenches from the solver's lambda balance gravity, sum of forces
//    = -m g and sum of moments about the world origin = -(c x m g).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "algorithms/constrained_aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

struct Named {
  const char* name;
  const char* urdf;
  const char* layout;
};
// 3d points on a floating base, 6d welds on a floating humanoid, two welds on one link.
const Named kSystems[] = {
    {"example quadruped", "generated/quadruped/quadruped.urdf", "generated/quadruped/layout.yaml"},
    {"example humanoid", "generated/humanoid/humanoid.urdf", "generated/humanoid/layout.yaml"},
    {"floating arm two welds", "tests/data/analytic/floating_arm.urdf", "tests/data/analytic/floating_arm_two_welds.yaml"},
};

System load(const Named& n) { return loadSystem(test::sourceDir() + "/" + n.urdf, test::sourceDir() + "/" + n.layout); }

Mat3 rotationOf(const VecX& X, Eigen::Index k) {
  Mat3 R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = X[12 * k + 3 * r + c];
  return R;
}

// Error of the central difference: h^2/6 |third derivative| + u/h per unit
// reach of the frame (h = 1e-5: 1.7e-11 + 1.1e-11), times 10 for the constants;
// each wrench entry multiplies it, so the bound scales with sum |W|.
TEST(ConstraintWrenches, MappedThroughTheWorldJacobiansTheySumToMinusJtLambda) {
  const double h = 1e-5;
  for (const Named& n : kSystems) {
    SCOPED_TRACE(n.name);
    const System sys = load(n);
    const Model& m = sys.model;
    Data d(sys);
    std::mt19937 rng(20261202);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 3; ++trial) {
      const State s = test::randomState(m, rng);
      VecX lambda(sys.nc);
      for (int k = 0; k < sys.nc; ++k) lambda[k] = 10 * normal(rng);
      const VecX W = constraintWrenches(sys, d, s.q, lambda);
      const VecX X0 = constraintPlacements(sys, d, s.q);
      const VecX expected = -constraintJacobianRows(sys, d, s.q).transpose() * lambda;
      VecX mapped = VecX::Zero(m.nv);
      double reach = 1;
      for (std::size_t k = 0; k < sys.constraints.size(); ++k)
        reach = std::max(reach, 1 + X0.segment<3>(12 * Eigen::Index(k) + 9).norm());
      for (int col = 0; col < m.nv; ++col) {
        const VecX e = VecX::Unit(m.nv, col) * h;
        const VecX Xp = constraintPlacements(sys, d, test::integrate(m, s.q, e));
        const VecX Xm = constraintPlacements(sys, d, test::integrate(m, s.q, -e));
        for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
          const Eigen::Index kk = Eigen::Index(k);
          const Vec3 velocity = (Xp.segment<3>(12 * kk + 9) - Xm.segment<3>(12 * kk + 9)) / (2 * h);
          const Vec3 omega = test::vee((rotationOf(Xp, kk) - rotationOf(Xm, kk)) * rotationOf(X0, kk).transpose()) / (2 * h);
          mapped[col] += velocity.dot(W.segment<3>(6 * kk)) + omega.dot(W.segment<3>(6 * kk + 3));
        }
      }
      const double tol = 10 * (h * h / 6 + test::kEps / h) * reach * W.cwiseAbs().sum();
      EXPECT_LE((mapped - expected).cwiseAbs().maxCoeff(), tol) << "state " << trial;
      EXPECT_GT(expected.cwiseAbs().maxCoeff(), 1.0);  // a real generalized force, not zeros
    }
  }
}

// Standing still: the torques tau = h(q, 0) + J^T lambda* with the base rows
// of tau zero (lambda* the least-norm multipliers that carry the base's
// gravity load) make qdd = 0, lambda = lambda* the answer (J has full row
// rank at these states, so it is unique); constrainedABA at K = 60, mu = 1e4
// converges to it (each update shrinks the error by 1 / (1 + mu sigma_min(G)),
// far below round-off after 60). Then Newton and Euler for the whole robot at
// rest: sum F_k = -m g, sum (p_k x F_k + T_k) = -(c x m g). Tolerance: the
// solve's forward error, c n u kappa(M + mu J^T J) (below 1e-7 relative at
// these states), of the total load m |g| (and m |g| |c| for the moments).
TEST(ConstraintWrenches, StandingStillTheyBalanceGravity) {
  for (const Named& n : kSystems) {
    SCOPED_TRACE(n.name);
    const System sys = load(n);
    const Model& m = sys.model;
    ASSERT_TRUE(m.floatingBase);
    Data d(sys);
    std::mt19937 rng(20261203);
    for (int trial = 0; trial < 3; ++trial) {
      const VecX q = test::randomState(m, rng).q, v = VecX::Zero(m.nv);
      const VecX hq = nonLinearEffects(sys, d, q, v);
      const MatX J = constraintJacobianRows(sys, d, q);
      const MatX A = J.leftCols(6).transpose();  // base rows of J^T
      const VecX lambdaStar = -A.transpose() * (A * A.transpose()).ldlt().solve(hq.head(6));
      VecX tau = hq + J.transpose() * lambdaStar;
      ASSERT_LE(tau.head(6).cwiseAbs().maxCoeff(), 1e-9 * hq.cwiseAbs().maxCoeff());
      tau.head(6).setZero();
      constrainedAba(sys, d, q, v, tau, 1e4, 60);
      const VecX lambda = d.lambda;
      const double qddMax = d.qdd.cwiseAbs().maxCoeff();
      const VecX W = constraintWrenches(sys, d, q, lambda);
      const VecX X = constraintPlacements(sys, d, q);
      double mass = 0;
      Vec3 firstMoment = Vec3::Zero();  // sum m_i c_i in the world
      forwardKinematics(sys, d, q);
      for (int i = 1; i < m.numBodies(); ++i) {
        const Inertia& I = m.bodies[std::size_t(i)].inertia;
        SE3 com;
        com.p = I.com;
        mass += I.mass;
        firstMoment += I.mass * framePlacement(d, i, com).p;
      }
      Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
      for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
        const Eigen::Index kk = Eigen::Index(k);
        const Vec3 F = W.segment<3>(6 * kk), p = X.segment<3>(12 * kk + 9);
        force += F;
        moment += p.cross(F) + W.segment<3>(6 * kk + 3);
      }
      const Vec3 weight = mass * m.gravity;
      const double load = weight.norm();
      EXPECT_LE(qddMax, 1e-6) << "state " << trial << ": not at rest";
      EXPECT_LE((force + weight).norm(), 1e-7 * load) << "state " << trial << ": forces " << force.transpose();
      EXPECT_LE((moment + firstMoment.cross(m.gravity)).norm(), 1e-7 * load * (1 + firstMoment.norm() / mass))
          << "state " << trial;
    }
  }
}

// On a 3d point the torque rows are exactly zero; a weld's are -R lambda_ang.
TEST(ConstraintWrenches, PointsCarryNoTorque) {
  const System sys = load(kSystems[0]);
  Data d(sys);
  std::mt19937 rng(7);
  const VecX q = test::randomState(sys.model, rng).q;
  const VecX lambda = VecX::LinSpaced(sys.nc, -3.0, 4.0);
  const VecX W = constraintWrenches(sys, d, q, lambda);
  for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
    ASSERT_EQ(sys.constraints[k].rows(), 3);
    EXPECT_EQ(W.segment<3>(6 * Eigen::Index(k) + 3), Vec3::Zero());
    // |F| = |lambda_k|: a rotation keeps the norm
    EXPECT_NEAR(W.segment<3>(6 * Eigen::Index(k)).norm(), lambda.segment<3>(sys.constraints[k].row).norm(), 1e-13);
  }
}

}  // namespace
}  // namespace proxgen

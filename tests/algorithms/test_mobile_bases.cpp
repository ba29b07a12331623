// Mobile bases (issue 13 item 3): planar joints (URDF `planar`, layout
// `base: planar`) and free flyers declared in the URDF (`floating`), through
// every generic algorithm. Three systems, all in-tree:
//  - the example arm on `base: planar` (a mobile manipulator), tool in point
//    contact and base welded (tests/generated/layouts/arm_planar.yaml);
//  - planar_mobile.urdf: a planar joint from the world with a yawed, offset
//    joint frame, and a second planar joint below a moving body, tilted;
//  - floating_joint.urdf: a free flyer from the world declared in the file.
// Checked with the identities the other joint types pass (ABA inverts RNEA,
// M qdd + h = RNEA, Jacobians and constraint rows are finite-difference
// derivatives), against the dense reference, against the free flyer (a planar
// joint is a free flyer restricted to three directions), `base: floating`
// against the same free flyer in the file, and one closed form.
#include <fmt/format.h>

#include <algorithm>

#include "algorithms/aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "model/urdf.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kEps;
constexpr double kH = 1e-5;  // central differences: see test_identities.cpp for the bounds
constexpr int kStates = 3;

std::string source(const std::string& f) { return std::string(PROXGEN_TEST_SOURCE_DIR) + "/" + f; }
std::string good(const std::string& f) { return std::string(PROXGEN_TEST_DATA_DIR) + "/good/" + f; }

struct Named {
  std::string name;
  System sys;
};

std::vector<Named> systems() {
  return {{"arm_planar", loadSystem(source("generated/arm/arm.urdf"), source("tests/generated/layouts/arm_planar.yaml"))},
          {"planar_mobile", loadSystem(good("planar_mobile.urdf"), good("planar_mobile.yaml"))},
          {"floating_joint", loadSystem(good("floating_joint.urdf"), good("floating_joint.yaml"))}};
}

TEST(MobileBases, TheSystemsHoldTheJointsUnderTest) {
  // Without these the tests below would pass on robots without planar joints.
  const std::vector<Named> all = systems();
  EXPECT_EQ(all[0].sys.model.bodies[1].joint.type, JointType::Planar);
  EXPECT_EQ(all[0].sys.model.nq, all[0].sys.model.nv + 1);
  EXPECT_EQ(all[1].sys.model.bodies[1].joint.type, JointType::Planar);
  EXPECT_EQ(all[1].sys.model.bodies[3].joint.type, JointType::Planar);
  EXPECT_GT(all[1].sys.model.bodies[3].parent, 0);  // the planar joint below a moving body
  EXPECT_EQ(all[2].sys.model.bodies[1].joint.type, JointType::FreeFlyer);
  for (const Named& n : all) EXPECT_GT(n.sys.nc, 0) << n.name;
}

TEST(MobileBases, AbaInvertsRnea) {
  for (const Named& n : systems()) {
    Data d(n.sys);
    std::mt19937 rng(21);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(n.sys.model, rng);
      const VecX qdd = s.tau;
      const VecX back = aba(n.sys, d, s.q, s.v, rnea(n.sys, d, s.q, s.v, qdd));
      // Gaussian elimination on M: c n eps kappa_s(M), c = 10 (numerics.hpp).
      const double kappa = test::scaledCondition(crba(n.sys, d, s.q));
      EXPECT_LE(test::relErr(back, qdd), 10 * n.sys.model.nv * kEps * kappa) << n.name << " state " << st;
    }
  }
}

TEST(MobileBases, CrbaMatchesRnea) {
  for (const Named& n : systems()) {
    Data d(n.sys);
    std::mt19937 rng(22);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(n.sys.model, rng);
      const int nv = n.sys.model.nv;
      const MatX M = crba(n.sys, d, s.q);
      const VecX h = rnea(n.sys, d, s.q, s.v, VecX::Zero(nv));
      const VecX tau = rnea(n.sys, d, s.q, s.v, s.tau);
      // Two evaluations of the same sums in different orders: c n eps of the terms' size.
      const double scale = (M.cwiseAbs() * s.tau.cwiseAbs() + h.cwiseAbs() + tau.cwiseAbs()).maxCoeff();
      EXPECT_LE((M * s.tau + h - tau).cwiseAbs().maxCoeff(), 10 * nv * kEps * scale) << n.name;
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(M).eigenvalues().minCoeff(), 0.0) << n.name;
    }
  }
}

// The Jacobian columns of a planar joint are its body-frame directions
// (linear x, linear y, angular z): the derivative of the placements along
// q "+" t e_k (numerics.hpp's integrate moves the planar joint by exp of
// the planar twist). Tolerance as in test_identities.cpp: 10 (h^2/6 + eps/h) reach.
TEST(MobileBases, FrameJacobiansAreDerivativesOfPlacements) {
  for (const Named& n : systems()) {
    const Model& m = n.sys.model;
    Data d0(n.sys), dp(n.sys), dm(n.sys);
    std::mt19937 rng(23);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(m, rng);
      forwardKinematics(n.sys, d0, s.q);
      double reach = 1;
      for (const Frame& f : m.frames) reach = std::max(reach, 1 + framePlacement(d0, f.body, f.placement).p.norm());
      const double tol = 10 * (kH * kH / 6 + kEps / kH) * reach;
      for (int k = 0; k < m.nv; ++k) {
        const VecX e = VecX::Unit(m.nv, k) * kH;
        forwardKinematics(n.sys, dp, test::integrate(m, s.q, e));
        forwardKinematics(n.sys, dm, test::integrate(m, s.q, -e));
        for (const Frame& f : m.frames) {
          const MatX J = frameJacobian(n.sys, d0, f.body, f.placement);
          const SE3 T0 = framePlacement(d0, f.body, f.placement);
          const SE3 Tp = framePlacement(dp, f.body, f.placement), Tm = framePlacement(dm, f.body, f.placement);
          const Vec6 fd = stack(T0.R.transpose() * (Tp.p - Tm.p), test::vee(T0.R.transpose() * (Tp.R - Tm.R))) / (2 * kH);
          EXPECT_LE((fd - J.col(k)).cwiseAbs().maxCoeff(), tol) << n.name << " frame " << f.name << " column " << k;
        }
      }
    }
  }
}

// J qdd + gamma is the time derivative of the constraint velocities along
// q(t) = q "+" t v, v(t) = v + t qdd (see test_identities.cpp): this checks the
// planar joint's velocity-product terms (no joint bias: S is constant in the
// body frame). Tolerance 10 (h^2/6 Omega^2 + eps/h), Omega = 1 + sum |v|.
TEST(MobileBases, ConstraintRowsAreDerivativesOfConstraintVelocities) {
  for (const Named& n : systems()) {
    const System& sys = n.sys;
    const Model& m = sys.model;
    Data d0(sys), dp(sys), dm(sys);
    std::mt19937 rng(24);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(m, rng);
      const VecX qdd = s.tau;
      constraintJacobian(sys, d0, s.q, s.v);
      const VecX rows = d0.J * qdd + d0.gamma;
      forwardKinematics(sys, dp, test::integrate(m, s.q, kH * s.v), s.v + kH * qdd);
      forwardKinematics(sys, dm, test::integrate(m, s.q, -kH * s.v), s.v - kH * qdd);
      const VecX fd = test::constraintRowsByDifferences(sys, d0, dp, dm, kH);
      const double Omega = 1 + s.v.cwiseAbs().sum();
      EXPECT_LE(test::relErr(rows, fd), 10 * (kH * kH / 6 * Omega * Omega + kEps / kH)) << n.name << " state " << st;
    }
  }
}

// Every algorithm against the dense proximal iteration with the same mu and
// K (test_equivalence.cpp's check), with the round-off bounds of numerics.hpp.
// The penalty algorithms (cABA, proxLTLs) read lambda off mu times the rows'
// acceleration, so lambda's absolute error is mu |J| times qdd's: relative to
// max(1, |lambda|) that is qdd's bound times mu |J| max(1, |qdd|) / max(1,
// |lambda|), the bound verify/compare.cpp argues for the generated cABA's
// lambda (cabaLambdaBound). It matters where lambda is small against
// mu |J| |qdd| (the URDF floating joint: 1.1e-9 against 5.6e-10 under clang -O0).
TEST(MobileBases, AllAlgorithmsAgreeWithTheDenseIteration) {
  for (const Named& n : systems()) {
    Data d(n.sys);
    std::mt19937 rng(25);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState s = test::randomState(n.sys.model, rng);
      const DenseProblem p = assembleDense(n.sys, s.q, s.v, s.tau);
      for (double mu : {100.0, 1e4}) {
        const test::Bounds tol = test::roundoffBounds(p, mu);
        for (int K : {1, 3}) {
          VecX qRef, lRef;
          denseProx(p, mu, K, qRef, lRef);
          for (const test::Algorithm& a : test::kAlgorithms) {
            a.run(n.sys, d, s.q, s.v, s.tau, mu, K);
            const double bound = (a.primal ? tol.primal : tol.dual) + test::multiplierRoundoff(p, lRef);
            double amplify = 1.0;  // the penalty algorithms' lambda (above)
            if (a.primal && lRef.size())
              amplify = std::max(1.0, mu * p.J.cwiseAbs().maxCoeff() * std::max(1.0, qRef.cwiseAbs().maxCoeff()) /
                                          std::max(1.0, lRef.cwiseAbs().maxCoeff()));
            EXPECT_LE(test::relErr(d.qdd, qRef), bound) << n.name << " " << a.name << " mu " << mu << " K " << K;
            EXPECT_LE(test::relErr(d.lambda, lRef), bound * amplify)
                << n.name << " " << a.name << " mu " << mu << " K " << K;
          }
        }
      }
    }
  }
}

// A planar joint is a free flyer held to z = 0 and to rotations about z:
// with q_ff = [x y 0, rotation about z by yaw] and v_ff = P v (P the 6 x 3
// selection of linear x, linear y, angular z), M_planar = P^T M_ff P and
// h_planar = P^T h_ff (the same body, the same velocities; the holding forces
// are orthogonal to P). The arm on `base: planar` against the arm on
// `base: floating`: two different code paths (S = I and S = P) in every
// recursion. This checks S and the velocity-product terms; not the sense of
// the yaw in the placement, which M and h in body coordinates do not see (with
// gravity along z), and which the Jacobian and closed-form tests above and
// below check. Round-off: c n eps of the entries' size.
TEST(MobileBases, PlanarBaseIsARestrictedFreeFlyer) {
  const System planar = loadSystem(source("generated/arm/arm.urdf"), source("tests/generated/layouts/arm_planar.yaml"));
  const System ff = loadSystemWithoutLayout(source("generated/arm/arm.urdf"), true);
  const int np = planar.model.nv, nf = ff.model.nv;
  ASSERT_EQ(nf, np + 3);
  MatX P = MatX::Zero(nf, np);
  P(0, 0) = P(1, 1) = P(5, 2) = 1.0;
  for (int k = 3; k < np; ++k) P(k + 3, k) = 1.0;
  Data dp(planar), df(ff);
  std::mt19937 rng(26);
  for (int st = 0; st < kStates; ++st) {
    const test::RandomState s = test::randomState(planar.model, rng);
    VecX qf(ff.model.nq);
    const double yaw = std::atan2(s.q[3], s.q[2]);
    const Eigen::Quaterniond rot(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    qf << s.q[0], s.q[1], 0.0, rot.coeffs(), s.q.tail(planar.model.nq - 4);
    const VecX vf = P * s.v;
    const MatX Mp = crba(planar, dp, s.q), Mf = crba(ff, df, qf);
    const VecX hp = rnea(planar, dp, s.q, s.v, VecX::Zero(np)), hf = rnea(ff, df, qf, vf, VecX::Zero(nf));
    const double scale = std::max(Mf.cwiseAbs().maxCoeff(), hf.cwiseAbs().maxCoeff());
    EXPECT_LE((Mp - P.transpose() * Mf * P).cwiseAbs().maxCoeff(), 10 * nf * kEps * scale) << "state " << st;
    EXPECT_LE((hp - P.transpose() * hf).cwiseAbs().maxCoeff(), 10 * nf * kEps * scale) << "state " << st;
  }
}

// A floating joint in the URDF, from a massless world link with an <origin>
// X_T, is `base: floating` on the child link: the hull's placement is
// X_T M(q_file), its body-frame twist the same v (X_T is constant). So with
// q_base = [translation and quaternion of X_T M(q_file)] and the same v and
// tau, both give the same qdd (and M, h). Round-off of two different sums: c n
// eps kappa_s(M), c = 10.
TEST(MobileBases, FloatingJointInTheFileIsAFloatingBase) {
  const System file = loadSystemWithoutLayout(good("floating_joint.urdf"), false);
  // The same robot without the world link and its joint, on `base: floating`.
  const std::string hull = R"(<robot name="b">
  <link name="hull"><inertial><origin xyz="0.05 0 -0.02"/><mass value="4.0"/>
    <inertia ixx="0.1" ixy="0.005" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial></link>
  <joint name="arm_joint" type="revolute"><origin xyz="0.3 0 0"/><parent link="hull"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="20" velocity="3"/></joint>
  <link name="arm"><inertial><origin xyz="0.15 0 0"/><mass value="0.8"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.006" iyz="0" izz="0.006"/></inertial></link>
</robot>)";
  Layout floating;
  floating.floatingBase = true;
  const System base = bindLayout(parseUrdf(hull, "hull.urdf", BaseType::Floating), floating);
  ASSERT_EQ(file.model.nv, base.model.nv);
  ASSERT_EQ(file.model.bodies[1].joint.name, "hull_float");
  const SE3 XT = file.model.bodies[1].treePlacement;
  EXPECT_GT((XT.R - Mat3::Identity()).norm(), 0.1);  // the check below sees X_T
  Data df(file), db(base);
  std::mt19937 rng(27);
  for (int st = 0; st < kStates; ++st) {
    const test::RandomState s = test::randomState(file.model, rng);
    const SE3 M = file.model.jointPlacement(1, s.q);  // = X_T M(q_file)
    VecX qb = s.q;
    qb.head<3>() = M.p;
    qb.segment<4>(3) = Eigen::Quaterniond(M.R).coeffs();
    const VecX a = aba(file, df, s.q, s.v, s.tau), b = aba(base, db, qb, s.v, s.tau);
    const double kappa = test::scaledCondition(crba(file, df, s.q));
    EXPECT_LE(test::relErr(a, b), 10 * file.model.nv * kEps * kappa) << "state " << st;
  }
}

// A box on a planar joint (the world's x-y plane), centre of mass at c = (cx,
// 0, 0) in its frame, spinning at v = [0, 0, w] at yaw theta, gravity
// g = (gx, gy, gz), tau = 0. The joint holds z, roll and pitch; in the plane
// the only force is m (gx, gy) at the COM, so the COM accelerates by (gx, gy)
// and the angular acceleration is 0 (no moment about the COM). The origin o
// = COM - R c then accelerates by (gx, gy) - R (w x (w x c)) = (gx, gy) +
// w^2 R c, which in the body frame is R^T (gx, gy) + (w^2 cx, 0). Its linear
// velocity is 0, so the body-frame derivative of [vx, vy] is that
// acceleration: qdd = [(R^T g)_x + w^2 cx, (R^T g)_y, 0], whatever gz and the
// inertia (the joint absorbs gz). A sign error in the velocity-product terms
// flips w^2 cx; a wrong S or frame mixes the components.
TEST(MobileBases, SpinningBoxOnAPlanarJoint) {
  const double m = 2.0, cx = 0.3, w = 1.7, theta = 0.8;
  const std::string box = fmt::format(R"(<robot name="box"><link name="box"><inertial>
    <origin xyz="{} 0 0.1"/><mass value="{}"/><inertia ixx="0.05" ixy="0.01" ixz="0.02" iyy="0.07" iyz="0" izz="0.09"/>
    </inertial></link></robot>)",
                                      cx, m);
  Layout L;
  L.planarBase = true;
  L.hasGravity = true;
  L.gravity = Vec3(1.5, -2.0, -9.81);
  const System sys = bindLayout(parseUrdf(box, "box.urdf", BaseType::Planar), L);
  ASSERT_EQ(sys.model.nq, 4);
  ASSERT_EQ(sys.model.nv, 3);
  VecX q(4), v(3);
  q << 0.4, -0.7, std::cos(theta), std::sin(theta);
  v << 0, 0, w;
  const Mat3 R = Eigen::AngleAxisd(theta, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 g = R.transpose() * L.gravity;
  VecX expected(3);
  expected << g.x() + w * w * cx, g.y(), 0.0;
  Data d(sys);
  const DenseProblem p = assembleDense(sys, q, v, VecX::Zero(3));
  // One 3 x 3 solve with M: c n eps kappa_s(M), relative to |qdd| (about 3).
  const double tol = test::roundoffBounds(p, 1.0).dual;
  EXPECT_LE(test::relErr(aba(sys, d, q, v, VecX::Zero(3)), expected), tol);
  VecX qdd, lambda;
  denseExact(p, qdd, lambda);
  EXPECT_LE(test::relErr(qdd, expected), tol);
}

}  // namespace
}  // namespace proxgen

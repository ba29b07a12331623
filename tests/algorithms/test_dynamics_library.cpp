// The dynamics library (docs/dynamics.md): inverse dynamics with constraint
// forces, M^-1 by its O(n^2) recursion, the constraint placements, Jacobian and
// drift, the Delassus matrix and its damped inverse. Each is checked on every
// shared case and on the repository's own robots (the three examples, the
// analytic cases with gains and redundant rows, a prismatic + continuous arm)
// against the dense reference and against identities that tie it to a
// quantity computed by other code: the solvers' own answers, ABA, CRBA,
// finite differences of the placements.
//
// Round-off bounds follow tests/numerics.hpp: a backward-stable evaluation of
// a sum has error c n eps times the sum of the magnitudes of its terms (no
// condition number: residual checks); a solve's forward error is c n eps times
// the Jacobi-scaled condition kappa_s of the matrix it inverts; c = 10.
#include <Eigen/Cholesky>

#include "algorithms/aba.hpp"
#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/jacobians.hpp"
#include "algorithms/kinematics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/prox_pv.hpp"
#include "algorithms/rnea.hpp"
#include "model/layout.hpp"
#include "numerics.hpp"
#include "support.hpp"

namespace proxgen {
namespace {

using test::kEps;
constexpr double kC = 10.0;
constexpr int kStates = 3;

using Named = test::NamedSystem;

// Every shared case, then the repository's robots: the examples, the example
// quadruped with Baumgarte gains (a* != 0), the analytic floating arm with gains
// and with two welds on one link (rank 6 of 12 rows), four coplanar contacts on
// a box, and a fixed-base arm with prismatic and continuous joints (alone, and
// with a weld on the world and two constraints on one chain).
std::vector<Named> allSystems() {
  std::vector<Named> out = test::sharedAndRepositorySystems();
  const std::string src = test::sourceDir();
  const auto add = [&](const std::string& name, const std::string& urdf, const std::string& layout) {
    out.push_back({name, loadSystem(src + "/" + urdf, src + "/" + layout)});
  };
  add("arm3 prismatic+continuous", "tests/data/good/arm3.urdf", "tests/data/good/arm3_tool.yaml");
  // A weld on the world (zero rows of J: the rows of G are 0 and of Ginv mu),
  // a weld mid-chain and the tool point below it on the same chain.
  const test::TempFile world(".yaml");
  world.write("base: fixed\nconstraints:\n  - {name: ground, link: base_link, type: 6d}\n"
              "  - {name: upper, link: upper_arm, type: 6d, offset: {xyz: [0.1, 0.2, -0.1]}}\n"
              "  - {name: tool_point, link: tool, type: 3d, kp: 30, kd: 4, target: {xyz: [0.3, 0.1, 0.5]}}\n");
  out.push_back({"arm3 world weld + chain", loadSystem(src + "/tests/data/good/arm3.urdf", world.path())});
  return out;
}

// max_i sum_j |A_ij| |x_j|: the magnitude of the terms of A x.
double termScale(const MatX& A, const VecX& x) { return x.size() == 0 ? 0.0 : (A.cwiseAbs() * x.cwiseAbs()).maxCoeff(); }
double maxAbs(const VecX& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// The same quantity computed by two orders of operations: c n eps times the
// size of the terms summed (scale), never less than the size of the result.
double sumBound(int n, double scale) { return kC * n * kEps * std::max(1.0, scale); }

TEST(DynamicsLibrary, InverseDynamicsReturnsTauAtTheProxPvSolution) {
  PROXGEN_REQUIRE_MODELS();
  int pushed = 0;  // states where the forces matter: the check below is not vacuous
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys), mine(sys);
    std::mt19937 rng(21);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      // At every K proxPV returns qdd = qdd_free - M^-1 J^T lambda for the
      // lambda it returns, so M qdd + h + J^T lambda = tau exactly (in exact
      // arithmetic): the identity holds converged (K = 200) or not (K = 3).
      for (int K : {3, 200}) {
        proxPv(sys, d, x.q, x.v, x.tau, 1e4, K);
        const VecX qdd = d.qdd, lambda = d.lambda;
        const VecX tau = inverseDynamics(sys, mine, x.q, x.v, qdd, &lambda);
        // Both sides are backward-stable sums (ABA is elimination on M; RNEA a
        // sum of body forces): error c n eps (|M||qdd| + |h| + |J^T||lambda| + |tau|).
        const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
        const double scale = termScale(p.M, qdd) + maxAbs(p.h) + termScale(p.J.transpose(), lambda) + maxAbs(x.tau);
        EXPECT_LE(maxAbs(tau - x.tau), sumBound(sys.model.nv, scale)) << s.name << " state " << st << " K " << K;
        // A dropped or mis-signed J^T lambda would be off by |J^T lambda|:
        // the check can fail whenever the constraints push the joints at all.
        if (sys.nc > 0 && maxAbs(p.J.transpose() * lambda) > 1000 * sumBound(sys.model.nv, scale)) {
          const VecX tauNoForce = inverseDynamics(sys, mine, x.q, x.v, qdd, nullptr);
          EXPECT_GT(maxAbs(tauNoForce - x.tau), 100 * sumBound(sys.model.nv, scale)) << s.name;
          ++pushed;
        }
      }
    }
  }
  EXPECT_GT(pushed, 0);
}

TEST(DynamicsLibrary, FreeMotionSatisfiesTheEquationOfMotion) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys);
    std::mt19937 rng(22);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const VecX qddFree = aba(sys, d, x.q, x.v, x.tau);
      const MatX M = crba(sys, d, x.q);
      const VecX h = nonLinearEffects(sys, d, x.q, x.v);
      const double scale = termScale(M, qddFree) + maxAbs(h) + maxAbs(x.tau);
      // Residual of a backward-stable solve: c n eps times its terms (above).
      EXPECT_LE(maxAbs(M * qddFree + h - x.tau), sumBound(sys.model.nv, scale)) << s.name << " state " << st;
      EXPECT_LE(maxAbs(inverseDynamics(sys, d, x.q, x.v, qddFree, nullptr) - x.tau), sumBound(sys.model.nv, scale))
          << s.name << " state " << st;
    }
  }
}

TEST(DynamicsLibrary, InverseDynamicsMatchesTheDenseReference) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys);
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-10, 10);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const VecX qdd = x.tau;  // any acceleration in [-1, 1]
      VecX lambda(sys.nc);
      for (int r = 0; r < sys.nc; ++r) lambda[r] = u(rng);
      const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
      const VecX ref = p.M * qdd + p.h + p.J.transpose() * lambda;
      const VecX tau = inverseDynamics(sys, d, x.q, x.v, qdd, &lambda);
      // Two evaluations of the same sums: c n eps times their terms.
      const double scale = termScale(p.M, qdd) + maxAbs(p.h) + termScale(p.J.transpose(), lambda);
      EXPECT_LE(maxAbs(tau - ref), sumBound(sys.model.nv, scale)) << s.name << " state " << st;
    }
  }
}

TEST(DynamicsLibrary, MassMatrixInverseInvertsCrba) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    const int n = sys.model.nv;
    Data d(sys);
    std::mt19937 rng(24);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const MatX M = crba(sys, d, x.q);
      const MatX Minv = massMatrixInverse(sys, d, x.q);
      EXPECT_EQ((Minv - Minv.transpose()).cwiseAbs().maxCoeff(), 0.0) << s.name << " not exactly symmetric";
      // M Minv = I: a residual, c n eps |M| |Minv| entrywise (Minv is ABA's
      // elimination run on the unit torques, backward stable).
      const MatX R = M * Minv - MatX::Identity(n, n);
      const MatX scale = M.cwiseAbs() * Minv.cwiseAbs();
      EXPECT_LE(R.cwiseAbs().maxCoeff(), sumBound(n, scale.maxCoeff())) << s.name << " state " << st;
      // Against the dense Cholesky inverse: forward error c n eps kappa_s(M)
      // (Jacobi-scaled condition, numerics.hpp), relative to the largest entry.
      const MatX ref = M.llt().solve(MatX::Identity(n, n));
      const double tol = kC * n * kEps * test::scaledCondition(M);
      EXPECT_LE((Minv - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff(), tol) << s.name << " state " << st;
    }
  }
}

TEST(DynamicsLibrary, PlacementsJacobianAndDriftMatchTheDenseReference) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    Data d(sys), ref(sys);
    std::mt19937 rng(25);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      constraintJacobian(sys, ref, x.q, x.v);  // frameJacobian's route, not fillJacobianRows'
      const MatX J = constraintJacobianRows(sys, d, x.q);
      const VecX gamma = constraintDrift(sys, d, x.q, x.v);
      // Same products in another order: c n eps times their size (relErr is
      // relative to max(1, |reference|)).
      const double tol = kC * sys.model.nv * kEps;
      EXPECT_LE(test::relErr(VecX(J.reshaped()), VecX(ref.J.reshaped())), tol) << s.name;
      EXPECT_LE(test::relErr(gamma, ref.gamma), tol * (1 + x.v.cwiseAbs().sum())) << s.name;
      const VecX X = constraintPlacements(sys, d, x.q);
      for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
        const Constraint& c = sys.constraints[k];
        forwardKinematics(sys, ref, x.q);
        const SE3 T = framePlacement(ref, c.body, c.placement);
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R;
        for (int e = 0; e < 9; ++e) R.data()[e] = X[12 * Eigen::Index(k) + e];
        EXPECT_EQ(Mat3(R), T.R) << s.name << " " << c.name << " rotation (row-major)";
        EXPECT_EQ(Vec3(X.segment<3>(12 * Eigen::Index(k) + 9)), T.p) << s.name << " " << c.name;
      }
    }
  }
}

// J against central differences of the placements on the configuration
// manifold (q "+" dq, free flyer M(q) exp(dq), numerics.hpp): the rows of C
// are its local twist, the origin velocity and angular velocity in C
// coordinates (3d: the first three). Step and bound as in
// test_identities.cpp: h = 1e-5, error 10 (h^2/6 + eps/h) reach.
TEST(DynamicsLibrary, JacobianIsTheDerivativeOfThePlacements) {
  PROXGEN_REQUIRE_MODELS();
  constexpr double kH = 1e-5;
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    const Model& m = sys.model;
    Data d0(sys), dp(sys), dm(sys);
    std::mt19937 rng(26);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(m, rng);
      const MatX J = constraintJacobianRows(sys, d0, x.q);
      const VecX X0 = constraintPlacements(sys, d0, x.q);
      double reach = 1;
      for (std::size_t k = 0; k < sys.constraints.size(); ++k) reach = std::max(reach, 1 + X0.segment<3>(12 * k + 9).norm());
      const double tol = 10 * (kH * kH / 6 + kEps / kH) * reach;
      const auto rot = [](const VecX& X, std::size_t k) {
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R;
        for (int e = 0; e < 9; ++e) R.data()[e] = X[12 * Eigen::Index(k) + e];
        return Mat3(R);
      };
      for (int col = 0; col < m.nv; ++col) {
        const VecX e = VecX::Unit(m.nv, col) * kH;
        const VecX Xp = constraintPlacements(sys, dp, test::integrate(m, x.q, e));
        const VecX Xm = constraintPlacements(sys, dm, test::integrate(m, x.q, -e));
        for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
          const Constraint& c = sys.constraints[k];
          const Mat3 R0 = rot(X0, k);
          const Vec3 dpos = Xp.segment<3>(12 * k + 9) - Xm.segment<3>(12 * k + 9);
          const Vec6 fd = stack(R0.transpose() * dpos, test::vee(R0.transpose() * (rot(Xp, k) - rot(Xm, k)))) / (2 * kH);
          const double err = (fd.head(c.rows()) - J.block(c.row, col, c.rows(), 1)).cwiseAbs().maxCoeff();
          EXPECT_LE(err, tol) << s.name << " " << c.name << " column " << col;
        }
      }
    }
  }
}

// The solvers hold K a_i = k per constraint (docs/algorithms.md §2); with the
// qdd they return, J qdd + gamma - a* must equal their own K a_i - k row by
// row at every K (the same constraint acceleration, computed from qdd here and
// from the sweep's body accelerations there), and at convergence its norm is
// the least-squares residual of the exact answer (0 for consistent rows).
TEST(DynamicsLibrary, JacobianAndDriftAreTheRowsTheSolversHold) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    if (sys.nc == 0) continue;
    Data d(sys), mine(sys), ref(sys);
    std::mt19937 rng(27);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
      const int Kconv = test::convergedIterations(p, 1e4, 1e-10);
      ASSERT_GT(Kconv, 0) << s.name;
      for (int K : {3, Kconv}) {
        proxPv(sys, d, x.q, x.v, x.tau, 1e4, K);
        VecX solverRows(sys.nc);
        for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
          const Constraint& c = sys.constraints[k];
          solverRows.segment(c.row, c.rows()) = d.terms[k].K * d.a[c.body] - d.terms[k].k;
        }
        const VecX qdd = d.qdd;
        const MatX J = constraintJacobianRows(sys, mine, x.q);
        const VecX gamma = constraintDrift(sys, mine, x.q, x.v);
        const VecX rows = J * qdd + gamma - p.aStar;
        // The same accelerations summed along the tree in another order:
        // c n eps (|J||qdd| + |gamma| + |a*|); the solver's body accelerations
        // also carry gravity, shifted out again by k: + |g|.
        const double scale = termScale(J, qdd) + maxAbs(gamma) + maxAbs(p.aStar) + sys.model.gravity.norm();
        EXPECT_LE(maxAbs(rows - solverRows), sumBound(sys.model.nv, scale)) << s.name << " state " << st << " K " << K;
        if (K == Kconv) {
          VecX qddExact, lambdaExact;
          denseExact(p, qddExact, lambdaExact);
          const double exactRes = (p.J * qddExact + p.gamma - p.aStar).norm();
          // qdd settled to 1e-10 relative (convergedIterations), plus the dual
          // round-off bound (numerics.hpp) on qdd, seen through |J|.
          const double tolQdd = 1e-10 + test::roundoffBounds(p, 1e4).dual;
          const double tol = termScale(J, VecX::Constant(sys.model.nv, tolQdd * std::max(1.0, maxAbs(qdd)))) * std::sqrt(double(sys.nc)) +
                             sumBound(sys.model.nv, scale);
          EXPECT_LE(std::abs(rows.norm() - exactRes), tol) << s.name << " state " << st;
        }
      }
    }
  }
}

TEST(DynamicsLibrary, DelassusMatchesTheDenseReference) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    if (sys.nc == 0) continue;
    Data d(sys);
    std::mt19937 rng(28);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
      const Eigen::LLT<MatX> llt(p.M);
      const MatX Gref = p.J * llt.solve(p.J.transpose());
      // Forward error of a solve with M: c n eps kappa_s(M), relative to |G|.
      const double tol = kC * sys.model.nv * kEps * test::scaledCondition(p.M);
      const double Gmax = Gref.cwiseAbs().maxCoeff();
      const MatX G = delassus(sys, d, x.q);
      EXPECT_EQ((G - G.transpose()).cwiseAbs().maxCoeff(), 0.0) << s.name;
      EXPECT_LE((G - Gref).cwiseAbs().maxCoeff(), tol * Gmax) << s.name << " dense route, state " << st;
      // The recursion without penalty is G itself; with one, J M_mu^-1 J^T,
      // whose solve has the condition of M_mu = M + mu J^T J.
      MatX Grec(sys.nc, sys.nc);
      delassusRecursion(sys, d, x.q, 0.0, Grec);
      EXPECT_LE((Grec - Gref).cwiseAbs().maxCoeff(), tol * Gmax) << s.name << " recursion, state " << st;
      for (double mu : {100.0, 1e4}) {
        const MatX Mmu = p.M + mu * p.J.transpose() * p.J;
        const MatX ref = p.J * Mmu.llt().solve(p.J.transpose());
        delassusRecursion(sys, d, x.q, mu, Grec);
        const double tolMu = kC * sys.model.nv * kEps * test::scaledCondition(Mmu);
        EXPECT_LE((Grec - ref).cwiseAbs().maxCoeff(), tolMu * ref.cwiseAbs().maxCoeff())
            << s.name << " penalised recursion mu " << mu << " state " << st;
      }
    }
  }
}

// (G + I/mu) Ginv = I. Ginv = mu I - mu^2 Omega, Omega = J M_mu^-1 J^T with
// |Omega| <= 1/mu: an error c n eps kappa_s(M_mu) |Omega| in Omega is
// c n eps kappa_s(M_mu) mu in Ginv, and (|G| + 1/mu) times that in the residual.
TEST(DynamicsLibrary, DelassusInverseInvertsTheDampedDelassus) {
  PROXGEN_REQUIRE_MODELS();
  for (const Named& s : allSystems()) {
    const System& sys = s.sys;
    if (sys.nc == 0) continue;
    Data d(sys);
    std::mt19937 rng(29);
    for (int st = 0; st < kStates; ++st) {
      const test::RandomState x = test::randomState(sys.model, rng);
      const DenseProblem p = assembleDense(sys, x.q, x.v, x.tau);
      const MatX G = p.J * p.M.llt().solve(p.J.transpose());
      for (double mu : {100.0, 1e4}) {
        MatX A = G;
        A.diagonal().array() += 1.0 / mu;
        const MatX Ginv = delassusInverse(sys, d, x.q, mu);
        EXPECT_EQ((Ginv - Ginv.transpose()).cwiseAbs().maxCoeff(), 0.0) << s.name;
        const MatX Mmu = p.M + mu * p.J.transpose() * p.J;
        const double errGinv = kC * sys.model.nv * kEps * test::scaledCondition(Mmu) * mu;
        const double Amax = A.cwiseAbs().rowwise().sum().maxCoeff();
        const MatX R = A * Ginv - MatX::Identity(sys.nc, sys.nc);
        EXPECT_LE(R.cwiseAbs().maxCoeff(), Amax * errGinv) << s.name << " mu " << mu << " state " << st;
        const MatX ref = A.llt().solve(MatX::Identity(sys.nc, sys.nc));
        EXPECT_LE((Ginv - ref).cwiseAbs().maxCoeff(), errGinv + kC * sys.nc * kEps * test::scaledCondition(A) * ref.cwiseAbs().maxCoeff())
            << s.name << " mu " << mu << " state " << st;
      }
    }
  }
}

}  // namespace
}  // namespace proxgen

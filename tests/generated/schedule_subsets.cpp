// Settings::active (issue 18 item 2) against separately generated solvers: the
// example quadruped's solver (generated/quadruped, four point feet) with each
// of the 16 schedules, against the solver generated for the layout of those
// feet alone (tests/generated/CMakeLists.txt writes the 16 layouts), in double
// and in float, both algorithms, on the same inputs.
//
// What must hold, and why:
// - the inactive feet's lambda rows are exactly 0 (their penalty, right-hand
//   side, and Delassus rows and columns are multiplied by an exact 0);
// - qdd and the active feet's lambda equal the subset solver's to round-off.
//   Both print the same recursions; with the flags, the inactive feet's terms
//   are exact zeros (x + 0 = x, x * 1 = x), so what differs is only the order
//   of a few sums: the subset solver eliminates an unconstrained leg with the
//   bodies off the support, before the support's legs, so the trunk's
//   articulated inertia and bias add the four legs' shares in another order
//   (each sum within 3 u of its terms' magnitudes). That perturbs the solve by
//   round-off of the size the generic comparison bounds: the bound is
//   verify::boundsAt at the subset's conditioning (the one every generated
//   solver meets against the generic solver, verify/compare.cpp), twice: each
//   side is within it of the generic subset answer. The test prints the
//   largest distance in units of that bound and in ulps of the answer's
//   largest entry.
// - the all-active schedule and the subset of all four feet are the same
//   generated code (the flags multiply by exact ones): bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "algorithms/constraints.hpp"
#include "algorithms/data.hpp"
#include "harness_lib.hpp"
#include "quadruped.hpp"
#include "quadruped_float.hpp"
#include "quadruped_s0000_double.hpp"
#include "quadruped_s0000_float.hpp"
#include "quadruped_s0001_double.hpp"
#include "quadruped_s0001_float.hpp"
#include "quadruped_s0010_double.hpp"
#include "quadruped_s0010_float.hpp"
#include "quadruped_s0011_double.hpp"
#include "quadruped_s0011_float.hpp"
#include "quadruped_s0100_double.hpp"
#include "quadruped_s0100_float.hpp"
#include "quadruped_s0101_double.hpp"
#include "quadruped_s0101_float.hpp"
#include "quadruped_s0110_double.hpp"
#include "quadruped_s0110_float.hpp"
#include "quadruped_s0111_double.hpp"
#include "quadruped_s0111_float.hpp"
#include "quadruped_s1000_double.hpp"
#include "quadruped_s1000_float.hpp"
#include "quadruped_s1001_double.hpp"
#include "quadruped_s1001_float.hpp"
#include "quadruped_s1010_double.hpp"
#include "quadruped_s1010_float.hpp"
#include "quadruped_s1011_double.hpp"
#include "quadruped_s1011_float.hpp"
#include "quadruped_s1100_double.hpp"
#include "quadruped_s1100_float.hpp"
#include "quadruped_s1101_double.hpp"
#include "quadruped_s1101_float.hpp"
#include "quadruped_s1110_double.hpp"
#include "quadruped_s1110_float.hpp"
#include "quadruped_s1111_double.hpp"
#include "quadruped_s1111_float.hpp"
#include "support.hpp"
#include "verify/compare.hpp"

namespace {

using proxgen::VecX;

// One generated solver seen through double vectors (the namespace's types).
#define PROXGEN_SOLVER_TRAITS(ns)                             \
  struct Traits_##ns {                                        \
    using Scalar = ns::Scalar;                                \
    using Settings = ns::Settings;                            \
    using Workspace = ns::Workspace;                          \
    static constexpr int nq = ns::nq, nv = ns::nv, nc = ns::nc, ncons = ns::ncons; \
    static constexpr auto caba = &ns::constrained_aba;        \
    static constexpr auto pv = &ns::prox_pv;                  \
  };

template <class T>
void run(int algorithm, const proxgen::State& s, double mu, int K, const std::vector<bool>* active, VecX& qdd,
         VecX& lambda) {
  using S = typename T::Scalar;
  std::vector<S> q(T::nq), v(T::nv), tau(T::nv), a(T::nv), l(std::size_t(std::max(T::nc, 1)));
  for (int k = 0; k < T::nq; ++k) q[std::size_t(k)] = S(s.q[k]);
  for (int k = 0; k < T::nv; ++k) v[std::size_t(k)] = S(s.v[k]), tau[std::size_t(k)] = S(s.tau[k]);
  typename T::Settings settings;
  settings.mu = S(mu);
  settings.iterations = K;
  if (active)
    for (int k = 0; k < T::ncons; ++k) settings.active[k] = active->at(std::size_t(k));
  static typename T::Workspace w;
  (algorithm == 0 ? T::caba : T::pv)(q.data(), v.data(), tau.data(), settings, w, a.data(), l.data());
  qdd.resize(T::nv);
  lambda.resize(T::nc);
  for (int k = 0; k < T::nv; ++k) qdd[k] = double(a[std::size_t(k)]);
  for (int k = 0; k < T::nc; ++k) lambda[k] = double(l[std::size_t(k)]);
}

using Runner = void (*)(int, const proxgen::State&, double, int, const std::vector<bool>*, VecX&, VecX&);

PROXGEN_SOLVER_TRAITS(quadruped)
PROXGEN_SOLVER_TRAITS(quadruped_float)
#define PROXGEN_SUBSET(bits)                        \
  PROXGEN_SOLVER_TRAITS(quadruped_s##bits##_double) \
  PROXGEN_SOLVER_TRAITS(quadruped_s##bits##_float)
PROXGEN_SUBSET(0000)
PROXGEN_SUBSET(0001)
PROXGEN_SUBSET(0010)
PROXGEN_SUBSET(0011)
PROXGEN_SUBSET(0100)
PROXGEN_SUBSET(0101)
PROXGEN_SUBSET(0110)
PROXGEN_SUBSET(0111)
PROXGEN_SUBSET(1000)
PROXGEN_SUBSET(1001)
PROXGEN_SUBSET(1010)
PROXGEN_SUBSET(1011)
PROXGEN_SUBSET(1100)
PROXGEN_SUBSET(1101)
PROXGEN_SUBSET(1110)
PROXGEN_SUBSET(1111)

struct Subset {
  const char* bits;  // lf rf lh rh, the layout order
  Runner dbl, flt;
};
#define PROXGEN_SUBSET_ENTRY(bits) \
  Subset{#bits, run<Traits_quadruped_s##bits##_double>, run<Traits_quadruped_s##bits##_float>}
const Subset kSubsets[] = {
    PROXGEN_SUBSET_ENTRY(0000), PROXGEN_SUBSET_ENTRY(0001), PROXGEN_SUBSET_ENTRY(0010), PROXGEN_SUBSET_ENTRY(0011),
    PROXGEN_SUBSET_ENTRY(0100), PROXGEN_SUBSET_ENTRY(0101), PROXGEN_SUBSET_ENTRY(0110), PROXGEN_SUBSET_ENTRY(0111),
    PROXGEN_SUBSET_ENTRY(1000), PROXGEN_SUBSET_ENTRY(1001), PROXGEN_SUBSET_ENTRY(1010), PROXGEN_SUBSET_ENTRY(1011),
    PROXGEN_SUBSET_ENTRY(1100), PROXGEN_SUBSET_ENTRY(1101), PROXGEN_SUBSET_ENTRY(1110), PROXGEN_SUBSET_ENTRY(1111),
};

void expectSubsetsMatch(bool isFloat) {
  const proxgen::System sys = proxgen::test::loadSolverSystem(nullptr, PROXGEN_SOLVER_URDF, PROXGEN_SOLVER_LAYOUT);
  ASSERT_EQ(int(sys.constraints.size()), 4);
  const Runner full = isFloat ? run<Traits_quadruped_float> : run<Traits_quadruped>;
  const double u = isFloat ? 5.9604644775390625e-08 : 1.1102230246251565e-16;
  std::mt19937 rng(20261205);
  double worstRatio = 0, worstUlps[2][2] = {};  // per algorithm, per mu
  for (const Subset& sub : kSubsets) {
    std::vector<bool> active(4);
    for (std::size_t k = 0; k < 4; ++k) active[k] = sub.bits[k] == '1';
    const proxgen::System subSys = proxgen::activeSubsystem(sys, active);
    const std::vector<int> kept = proxgen::activeRows(sys, active);
    proxgen::Data dense(subSys);
    const bool all = std::string(sub.bits) == "1111";
    for (int n = 0; n < 5; ++n) {
      const proxgen::State s = proxgen::verify::roundedToScalar(proxgen::test::randomState(sys.model, rng), isFloat);
      const proxgen::verify::Conditioning cond = proxgen::verify::conditioningAt(subSys, dense, s, isFloat);
      for (double mu : {100.0, 1e4}) {
        const proxgen::verify::Bounds b = proxgen::verify::boundsAt(cond, mu);
        for (int K : {0, 1, 3, 20}) {
          for (int a = 0; a < 2; ++a) {
            const std::string where = std::string("feet ") + sub.bits + ", algorithm " + std::to_string(a) + ", state " +
                                      std::to_string(n) + ", mu " + std::to_string(mu) + ", K " + std::to_string(K);
            VecX qdd, lambda, qddSub, lambdaSub;
            full(a, s, mu, K, &active, qdd, lambda);
            (isFloat ? sub.flt : sub.dbl)(a, s, mu, K, nullptr, qddSub, lambdaSub);
            VecX lambdaKept(Eigen::Index(kept.size()));
            for (std::size_t r = 0; r < kept.size(); ++r) lambdaKept[Eigen::Index(r)] = lambda[kept[r]];
            for (int r = 0; r < sys.nc; ++r)
              if (std::find(kept.begin(), kept.end(), r) == kept.end()) {
                EXPECT_EQ(lambda[r], 0.0) << "inactive row " << r << ", " << where;
              }
            if (all) {  // the same code: the same bits
              EXPECT_EQ(qdd, qddSub) << where;
              EXPECT_EQ(lambdaKept, lambdaSub) << where;
              continue;
            }
            // Twice the generic comparison's bound (see the top of the file);
            // constrainedABA's lambda carries mu |J| times qdd's error.
            const double qddBound = 2 * (a == 0 ? b.primal : b.dual);
            const double lambdaBound =
                2 * (a == 0 ? proxgen::verify::cabaLambdaBound(subSys, cond, b, qddSub, lambdaSub) : b.dual);
            const double eq = proxgen::verify::relErr(qdd, qddSub);
            EXPECT_LE(eq, qddBound) << "qdd, " << where;
            worstRatio = std::max(worstRatio, eq / qddBound);
            double& ulps = worstUlps[a][mu > 100 ? 1 : 0];
            ulps = std::max(ulps, eq / u);
            if (subSys.nc > 0) {
              const double el = proxgen::verify::relErr(lambdaKept, lambdaSub);
              EXPECT_LE(el, lambdaBound) << "lambda, " << where;
              worstRatio = std::max(worstRatio, el / lambdaBound);
              ulps = std::max(ulps, el / u);
            }
          }
        }
      }
    }
  }
  std::printf("%s: largest distance to the subset solvers %.2f of the bound; in u (relative to the answer's "
              "largest entry): constrained_aba %.0f (mu 100) %.0f (mu 1e4), prox_pv %.0f (mu 100) %.0f (mu 1e4)\n",
              isFloat ? "float" : "double", worstRatio, worstUlps[0][0], worstUlps[0][1], worstUlps[1][0], worstUlps[1][1]);
}

TEST(ScheduleSubsets, DoubleMatchesTheSolversGeneratedForEachSubset) { expectSubsetsMatch(false); }
TEST(ScheduleSubsets, FloatMatchesTheSolversGeneratedForEachSubset) { expectSubsetsMatch(true); }

}  // namespace

// The generated dynamics library against its generic twins in the same run,
// per case: <case>/<function>/generated and <case>/<function>/generic for
// inverse_dynamics (random qdd and lambda), nonlinear_effects, mass_matrix
// (= crba), mass_matrix_inverse, constraint_placements, constraint_jacobian,
// constraint_drift, delassus and delassus_inverse (mu = 1e4), and
// <case>/delassus_inverse/route_mass_matrix: (J M^-1 J^T + I/mu)^-1 formed
// from the generated mass_matrix and constraint_jacobian (Eigen's LLT of M,
// then the LLT of G + I/mu and its inverse). States (and qdd, lambda) are
// drawn before any timing and cycled inside the timed loop, as
// bench_suite.cpp does. The cases are those of joint_space.cmake
// (PROXGEN_BENCH_LIBRARY_CASES). Where CMake finds Pinocchio (bench/pinocchio.cmake),
// also <case>/<function>/pinocchio for inverse_dynamics (rnea, no constraint
// forces: the generated function does J^T lambda besides), nonlinear_effects,
// mass_matrix (crba, its upper triangle copied to the lower one, as the
// generated function returns the full matrix) and mass_matrix_inverse
// (computeMinverse, the same copy), and <case>/<function>/pinocchio_upper for
// the last two without the copy (crba in Pinocchio 3.7's default LOCAL
// convention), and mass_matrix/pinocchio_world for crba in its WORLD convention
// with the copy (bench_pinocchio.cpp, pinocchioJointSpace), on the same states and qdd.
// <case>/mass_matrix/zero_fill writes nv x nv zeros into mass_matrix's output
// buffer and nothing else: the cost of returning the full matrix.
//
//   proxgen_bench_joint_space [Google Benchmark flags]
//   proxgen_bench_joint_space --count CASE/FUNCTION/VARIANT N
// --count makes N calls of one benchmark's body and nothing else, for
// instructions per call under callgrind (bench/count_calls.py --library):
// everything but the N calls is the same for every N (and for every function
// of a case). Exit code 3: no such benchmark in this build.
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/delassus.hpp"
#include "algorithms/inverse_dynamics.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "bodies.hpp"
#include "cases/cases.hpp"
#include "joint_space_solvers.hpp"
#include "model/state.hpp"

#ifdef PROXGEN_BENCH_PINOCCHIO
namespace proxgen::bench {
// bench_pinocchio.cpp: one call of Pinocchio's `function` on state k (checked against the generic twin first).
std::function<void(int)> pinocchioJointSpace(const std::string& caseName, const System& sys,
                                             const std::vector<State>& states, const std::vector<VecX>& qdd,
                                             const std::string& function);
}  // namespace proxgen::bench
#endif

namespace {

using proxgen::bench::bodies;

constexpr double kMu = 1e4;  // the benchmarks' mu (bench/common.hpp)

// A case of cases.yaml with 1000 random states (a fixed seed), loaded once per
// case for the whole run (the suite's pool size, bench/common.hpp).
struct BenchCase {
  std::string name;
  proxgen::System sys;
  std::vector<proxgen::State> states;
};

const BenchCase* findCase(const std::string& name) {
  static std::vector<std::unique_ptr<BenchCase>> loaded;
  auto c = std::make_unique<BenchCase>();
  c->name = name;
  c->sys = proxgen::loadCaseSystem(proxgen::loadCase(PROXGEN_BENCH_CASES_FILE, name));
  std::mt19937 rng(1);
  for (int k = 0; k < 1000; ++k) c->states.push_back(proxgen::randomState(c->sys.model, rng));
  loaded.push_back(std::move(c));
  return loaded.back().get();
}

// One case's inputs in the generated Scalar and in double (VecX), kept for the whole run.
template <class Scalar>
struct Inputs {
  int n = 0, nq = 0, nv = 0, nc = 0;
  std::vector<Scalar> q, v, qdd, lambda;
  std::vector<proxgen::VecX> qdd64, lambda64;
  const Scalar* at(const std::vector<Scalar>& x, int size, int k) const { return x.data() + std::size_t(k) * size; }
};

template <class Scalar>
std::shared_ptr<Inputs<Scalar>> inputsOf(const BenchCase& c) {
  auto in = std::make_shared<Inputs<Scalar>>();
  const proxgen::Model& m = c.sys.model;
  in->n = int(c.states.size());
  in->nq = m.nq, in->nv = m.nv, in->nc = c.sys.nc;
  std::mt19937 rng(20261201);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const proxgen::State& s : c.states) {
    proxgen::VecX qdd(m.nv), lambda(c.sys.nc);
    for (int k = 0; k < m.nv; ++k) qdd[k] = normal(rng);
    for (int k = 0; k < c.sys.nc; ++k) lambda[k] = 10.0 * normal(rng);
    for (int k = 0; k < m.nq; ++k) in->q.push_back(Scalar(s.q[k]));
    for (int k = 0; k < m.nv; ++k) in->v.push_back(Scalar(s.v[k])), in->qdd.push_back(Scalar(qdd[k]));
    for (int k = 0; k < c.sys.nc; ++k) in->lambda.push_back(Scalar(lambda[k]));
    in->qdd64.push_back(qdd);
    in->lambda64.push_back(lambda);
  }
  return in;
}

// The route through the generated mass matrix: Eigen's fixed-size LLT of M
// (what a user would write with the generated pieces), J M^-1 J^T + I/mu, its
// LLT and inverse. The work matrices live for the whole run.
template <class G>
struct Route {
  using Scalar = typename G::Scalar;
  using MatM = Eigen::Matrix<Scalar, G::nv, G::nv, Eigen::RowMajor>;
  using MatJ = Eigen::Matrix<Scalar, G::nc, G::nv, Eigen::RowMajor>;
  using MatC = Eigen::Matrix<Scalar, G::nc, G::nc>;
  MatM M;
  MatJ J;
  Eigen::Matrix<Scalar, G::nv, G::nc> MinvJt;
  MatC A, Ginv;
  Eigen::LLT<Eigen::Matrix<Scalar, G::nv, G::nv>> lltM;
  Eigen::LLT<MatC> lltA;
  void operator()(const Scalar* q, typename G::Workspace& w) {
    G::mass_matrix(q, w, M.data());
    G::constraint_jacobian(q, w, J.data(), G::all_active);
    lltM.compute(M);
    MinvJt = lltM.solve(J.transpose());
    A.noalias() = J * MinvJt;
    A.diagonal().array() += Scalar(1.0 / kMu);
    lltA.compute(A);
    Ginv.setIdentity();
    lltA.solveInPlace(Ginv);
  }
};

template <class G>
void registerCase(const char* name) {
  using Scalar = typename G::Scalar;
  const BenchCase& c = *findCase(name);
  const auto in = inputsOf<Scalar>(c);
  const auto ws = std::make_shared<typename G::Workspace>();
  const int nv = in->nv, nc = in->nc;
  const auto out = std::make_shared<std::vector<Scalar>>(std::size_t(std::max({nv * nv, nc * nc, 12 * G::ncons, 1})));
  const auto data = std::make_shared<proxgen::Data>(c.sys);
  const auto settings = std::make_shared<typename G::Settings>();
  settings->mu = Scalar(kMu);
  const auto route = std::make_shared<Route<G>>();
  const std::string base = c.name + "/";
  const auto reg = [&](const std::string& what, std::function<void(int)> call) {
    bodies().push_back({base + what, in->n, nv, nc, std::move(call), {}});
  };
  const auto q = [in](int k) { return in->at(in->q, in->nq, k); };
  const auto v = [in](int k) { return in->at(in->v, in->nv, k); };
  const auto s = [&c](int k) -> const proxgen::State& { return c.states[std::size_t(k)]; };
  reg("inverse_dynamics/generated", [=](int k) {
    G::inverse_dynamics(q(k), v(k), in->at(in->qdd, nv, k), in->at(in->lambda, nc, k), *ws, out->data(), G::all_active);
    benchmark::DoNotOptimize(out->data());
  });
  reg("inverse_dynamics/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::inverseDynamics(c.sys, *data, s(k).q, s(k).v, in->qdd64[std::size_t(k)],
                                                      nc ? &in->lambda64[std::size_t(k)] : nullptr)
                                 .data());
  });
  reg("nonlinear_effects/generated", [=](int k) {
    G::nonlinear_effects(q(k), v(k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("nonlinear_effects/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::nonLinearEffects(c.sys, *data, s(k).q, s(k).v).data());
  });
  reg("mass_matrix/generated", [=](int k) {
    G::mass_matrix(q(k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("mass_matrix/generic", [=, &c](int k) { benchmark::DoNotOptimize(proxgen::crba(c.sys, *data, s(k).q).data()); });
  // Writing all of M's nv x nv entries and nothing else (std::fill: glibc's memset), into the
  // buffer mass_matrix/generated writes: the floor of returning the full matrix, 56 KB on the
  // Atlas, more than a 48 KB first-level data cache (docs/benchmarks.md, "The full mass matrix").
  reg("mass_matrix/zero_fill", [=](int) {
    std::fill(out->data(), out->data() + std::size_t(nv) * std::size_t(nv), Scalar(0));
    benchmark::DoNotOptimize(out->data());
    benchmark::ClobberMemory();
  });
  reg("mass_matrix_inverse/generated", [=](int k) {
    G::mass_matrix_inverse(q(k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("mass_matrix_inverse/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::massMatrixInverse(c.sys, *data, s(k).q).data());
  });
  reg("constraint_placements/generated", [=](int k) {
    G::constraint_placements(q(k), *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("constraint_placements/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::constraintPlacements(c.sys, *data, s(k).q).data());
  });
  reg("constraint_jacobian/generated", [=](int k) {
    G::constraint_jacobian(q(k), *ws, out->data(), G::all_active);
    benchmark::DoNotOptimize(out->data());
  });
  reg("constraint_jacobian/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::constraintJacobianRows(c.sys, *data, s(k).q).data());
  });
  reg("constraint_drift/generated", [=](int k) {
    G::constraint_drift(q(k), v(k), *ws, out->data(), G::all_active);
    benchmark::DoNotOptimize(out->data());
  });
  reg("constraint_drift/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::constraintDrift(c.sys, *data, s(k).q, s(k).v).data());
  });
  reg("delassus/generated", [=](int k) {
    G::delassus(q(k), *ws, out->data(), G::all_active);
    benchmark::DoNotOptimize(out->data());
  });
  reg("delassus/generic", [=, &c](int k) { benchmark::DoNotOptimize(proxgen::delassus(c.sys, *data, s(k).q).data()); });
  reg("delassus_inverse/generated", [=](int k) {
    G::delassus_inverse(q(k), *settings, *ws, out->data());
    benchmark::DoNotOptimize(out->data());
  });
  reg("delassus_inverse/generic", [=, &c](int k) {
    benchmark::DoNotOptimize(proxgen::delassusInverse(c.sys, *data, s(k).q, kMu).data());
  });
  reg("delassus_inverse/route_mass_matrix", [=](int k) {
    (*route)(q(k), *ws);
    benchmark::DoNotOptimize(route->Ginv.data());
  });
#ifdef PROXGEN_BENCH_PINOCCHIO
  // The same states and qdd (in double: the inputs the generic twins read).
  for (const char* fn : {"inverse_dynamics", "nonlinear_effects", "mass_matrix", "mass_matrix_inverse"})
    reg(std::string(fn) + "/pinocchio", proxgen::bench::pinocchioJointSpace(c.name, c.sys, c.states, in->qdd64, fn));
  for (const char* fn : {"mass_matrix", "mass_matrix_inverse"})
    reg(std::string(fn) + "/pinocchio_upper",
        proxgen::bench::pinocchioJointSpace(c.name, c.sys, c.states, in->qdd64, std::string(fn) + "_upper"));
  reg("mass_matrix/pinocchio_world",
      proxgen::bench::pinocchioJointSpace(c.name, c.sys, c.states, in->qdd64, "mass_matrix_world"));
#endif
}

}  // namespace

// One generated namespace's functions as a type, for registerCase.
#define PROXGEN_BENCH_API(CASE, NS)                                                                             \
  namespace api_##CASE {                                                                                        \
  struct G {                                                                                                    \
    using Scalar = NS::Scalar;                                                                                  \
    using Workspace = NS::Workspace;                                                                            \
    using Settings = NS::Settings;                                                                              \
    static constexpr int nv = NS::nv, nc = NS::nc, ncons = NS::ncons;                                           \
    /* through a function pointer the flags' default argument is gone: every constraint active */               \
    static constexpr const bool* all_active = NS::all_active;                                                   \
    static constexpr auto inverse_dynamics = &NS::inverse_dynamics;                                             \
    static constexpr auto nonlinear_effects = &NS::nonlinear_effects;                                           \
    static constexpr auto mass_matrix = &NS::mass_matrix;                                                       \
    static constexpr auto mass_matrix_inverse = &NS::mass_matrix_inverse;                                       \
    static constexpr auto constraint_placements = &NS::constraint_placements;                                   \
    static constexpr auto constraint_jacobian = &NS::constraint_jacobian;                                       \
    static constexpr auto constraint_drift = &NS::constraint_drift;                                             \
    static constexpr auto delassus = &NS::delassus;                                                             \
    static constexpr auto delassus_inverse = &NS::delassus_inverse;                                             \
  };                                                                                                            \
  }
PROXGEN_BENCH_JOINT_SPACE_CASES(PROXGEN_BENCH_API)
#undef PROXGEN_BENCH_API

int main(int argc, char** argv) {
  const bool count = argc >= 2 && std::strcmp(argv[1], "--count") == 0;
  if (count && argc != 4) {
    std::fprintf(stderr, "usage: %s --count CASE/FUNCTION/VARIANT N\n", argv[0]);
    return 1;
  }
  // --count loads only its case: the same work whatever the function, so one
  // run with N = 0 is the baseline of all of them.
  const std::string only = count ? std::string(argv[2]).substr(0, std::string(argv[2]).find('/')) : "";
#define PROXGEN_BENCH_REGISTER(CASE, NS) \
  if (only.empty() || only == #CASE) registerCase<api_##CASE::G>(#CASE);
  PROXGEN_BENCH_JOINT_SPACE_CASES(PROXGEN_BENCH_REGISTER)
#undef PROXGEN_BENCH_REGISTER
  if (count) return proxgen::bench::countBody("proxgen_bench_joint_space", argv[2], std::stol(argv[3]));
  return proxgen::bench::runBodies(argc, argv);
}

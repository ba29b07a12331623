// The generated delassus_inverse, (G + I/mu)^-1 by the O(n + m^2) recursion
// without an m x m factorisation (docs/dynamics.md), against forming
// G + I/mu = J M^-1 J^T + I/mu from the generic pieces (CRBA for M,
// constraintJacobianRows for J, Eigen's LLT of M, then the LLT of G + I/mu and
// its inverse), and against the generic recursion (delassusInverse), in the
// same run on the same states. The solvers are the test solvers of
// tests/generated that hold the constraint functions (written into
// delassus_solvers.hpp by bench/CMakeLists.txt).
//   build/bench/proxgen_bench_delassus --benchmark_min_time=0.2
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

#include "algorithms/constraint_kinematics.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/delassus.hpp"
#include "cases/cases.hpp"
#include "model/layout.hpp"
#include "model/state.hpp"

// One solver's functions as a type, for the template below.
#define PROXGEN_DELASSUS_API(ns)                                                                         \
  namespace ns {                                                                                         \
  struct Api {                                                                                           \
    using Scalar = ns::Scalar;                                                                           \
    using Workspace = ns::Workspace;                                                                     \
    using Settings = ns::Settings;                                                                       \
    static constexpr int nc = ns::nc;                                                                    \
    static void delassus_inverse(const Scalar* q, const Settings& s, Workspace& w, Scalar* G) noexcept { \
      ns::delassus_inverse(q, s, w, G);                                                                  \
    }                                                                                                    \
  };                                                                                                     \
  }
#include "delassus_solvers.hpp"  // the solvers' headers, PROXGEN_DELASSUS_API(ns) and PROXGEN_DELASSUS_CASES

namespace {

constexpr double kMu = 1e4;  // the benchmarks' mu (bench/common.hpp)
constexpr int kStates = 64;

std::vector<proxgen::State> states(const proxgen::Model& m) {
  std::mt19937 rng(20261201);
  std::vector<proxgen::State> out;
  for (int k = 0; k < kStates; ++k) out.push_back(proxgen::randomState(m, rng));
  return out;
}

template <class Gen>
void generated(benchmark::State& st, const proxgen::System& sys) {
  const std::vector<proxgen::State> pool = states(sys.model);
  std::vector<std::vector<typename Gen::Scalar>> qs;
  for (const proxgen::State& s : pool) qs.emplace_back(s.q.data(), s.q.data() + s.q.size());
  static typename Gen::Workspace w;
  typename Gen::Settings s;
  s.mu = kMu;
  std::vector<typename Gen::Scalar> Ginv(std::size_t(Gen::nc * Gen::nc));
  int k = 0;
  for (auto _ : st) {
    Gen::delassus_inverse(qs[std::size_t(k)].data(), s, w, Ginv.data());
    benchmark::DoNotOptimize(Ginv.data());
    benchmark::ClobberMemory();
    k = (k + 1) % kStates;
  }
}

// J M^-1 J^T + I/mu formed from CRBA and J, factored, inverted (no allocation
// in the loop: the work matrices are sized once).
void genericDense(benchmark::State& st, const proxgen::System& sys) {
  const std::vector<proxgen::State> pool = states(sys.model);
  proxgen::Data d(sys);
  const int nv = sys.model.nv, nc = sys.nc;
  Eigen::LLT<proxgen::MatX> lltM(nv), lltA(nc);
  proxgen::MatX MinvJt(nv, nc), A(nc, nc), Ginv(nc, nc);
  const proxgen::MatX I = proxgen::MatX::Identity(nc, nc);
  int k = 0;
  for (auto _ : st) {
    const proxgen::VecX& q = pool[std::size_t(k)].q;
    proxgen::crba(sys, d, q);
    const proxgen::MatX& J = proxgen::constraintJacobianRows(sys, d, q);
    lltM.compute(d.M);
    MinvJt = J.transpose();
    lltM.solveInPlace(MinvJt);
    A.noalias() = J * MinvJt;
    A.diagonal().array() += 1.0 / kMu;
    lltA.compute(A);
    Ginv = I;
    lltA.solveInPlace(Ginv);
    benchmark::DoNotOptimize(Ginv.data());
    k = (k + 1) % kStates;
  }
}

void genericRecursion(benchmark::State& st, const proxgen::System& sys) {
  const std::vector<proxgen::State> pool = states(sys.model);
  proxgen::Data d(sys);
  int k = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(proxgen::delassusInverse(sys, d, pool[std::size_t(k)].q, kMu).data());
    k = (k + 1) % kStates;
  }
}

}  // namespace

int main(int argc, char** argv) {
  static std::vector<proxgen::System> systems;
  systems.reserve(16);
#define PROXGEN_DELASSUS_CASE(name, ns, load)                                                               \
  {                                                                                                         \
    systems.push_back(load);                                                                                \
    const proxgen::System* sys = &systems.back();                                                           \
    benchmark::RegisterBenchmark(name "/generated_delassus_inverse",                                        \
                                 [sys](benchmark::State& st) { generated<ns::Api>(st, *sys); });            \
    benchmark::RegisterBenchmark(name "/generic_dense_JMinvJt_llt",                                         \
                                 [sys](benchmark::State& st) { genericDense(st, *sys); });                  \
    benchmark::RegisterBenchmark(name "/generic_recursion", [sys](benchmark::State& st) { genericRecursion(st, *sys); }); \
  }
  PROXGEN_DELASSUS_CASES
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}

// States per second per core of the batched generated solvers (generate
// --batch W, docs/batch.md) against the scalar generated solver and against
// Pinocchio's constrainedABA / pv called in a loop (where the build found
// Pinocchio: bench/pinocchio.cmake), in the same run, on each shared case's
// state pool (common.hpp: 1000 random states, K = 3, mu = 1e4). Each variant
// solves the whole pool (scalar and Pinocchio: a loop of single calls;
// batched: one _many call), repeated until the variants together have run
// their share of time, best pass kept; the variants alternate so that
// frequency drift hits all. Variants: W = 4 and W = 8 at -march (with the
// W = 4 variant's scalar solver as the reference), and, where the build has
// it, W = 4 with its own scalar solver compiled with
// PROXGEN_BENCH_BATCH_AVX2_FLAGS (AVX2 without AVX-512). It also prints the
// largest difference of each batched answer from the scalar one (0 unless the
// compiler fused multiply-adds differently in the two, -ffp-contract:
// docs/batch.md, "Lane by lane").
//   proxgen_bench_batch [--min-time SECONDS] [--case NAME]...    (bench/RESULTS.md, "Batched solvers")
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common.hpp"
// The generated solvers (bench/CMakeLists.txt, PROXGEN_BENCH_BATCH_CASES): their headers.
#include "batch_includes.inc"

namespace proxgen::bench {

// n states in the plain layout: state k's q at q + k * nq, and so on.
using PoolSolve = std::function<void(int n, const double* q, const double* v, const double* tau, double* qdd,
                                     double* lambda)>;

// Per algorithm (0: constrained_aba, 1: prox_pv). The AVX2 pair is empty
// without that variant.
struct BatchEntry {
  const char* name;
  int nq, nv, nc;
  PoolSolve scalar[2], batch4[2], batch8[2], scalarAvx2[2], batch4Avx2[2];
};

template <class Settings>
Settings benchSettings() {
  Settings s;
  s.mu = kMu;
  s.iterations = kIterations;
  return s;
}

// The scalar solver of NS in a loop over the pool.
#define PROXGEN_BATCH_SCALAR(NS, FN)                                                                         \
  [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {             \
    static NS::Workspace w;                                                                                 \
    const auto s = benchSettings<NS::Settings>();                                                           \
    for (int k = 0; k < n; ++k)                                                                             \
      NS::FN(q + k * NS::nq, v + k * NS::nv, tau + k * NS::nv, s, w, qdd + k * NS::nv, lambda + k * NS::nc); \
  }
// The batched _many function FN of NS on the pool.
#define PROXGEN_BATCH_MANY(NS, FN)                                                               \
  [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) { \
    static NS::BatchWorkspace w;                                                                \
    NS::FN(n, q, v, tau, benchSettings<NS::Settings>(), w, qdd, lambda);                        \
  }

// The solvers generated with BATCH 4 (NS4) and BATCH 8 (NS8), and BATCH 4
// with the AVX2 flags (NSAVX2, _AVX2 form).
#define PROXGEN_BATCH_ENTRY(CASE, NS4, NS8)                                                     \
  BatchEntry {                                                                                  \
    CASE, NS4::nq, NS4::nv, NS4::nc,                                                            \
        {PROXGEN_BATCH_SCALAR(NS4, constrained_aba), PROXGEN_BATCH_SCALAR(NS4, prox_pv)},       \
        {PROXGEN_BATCH_MANY(NS4, constrained_aba_many), PROXGEN_BATCH_MANY(NS4, prox_pv_many)}, \
        {PROXGEN_BATCH_MANY(NS8, constrained_aba_many), PROXGEN_BATCH_MANY(NS8, prox_pv_many)}, {}, {}  \
  }
#define PROXGEN_BATCH_ENTRY_AVX2(CASE, NS4, NS8, NSAVX2)                                                 \
  BatchEntry {                                                                                           \
    CASE, NS4::nq, NS4::nv, NS4::nc,                                                                     \
        {PROXGEN_BATCH_SCALAR(NS4, constrained_aba), PROXGEN_BATCH_SCALAR(NS4, prox_pv)},                \
        {PROXGEN_BATCH_MANY(NS4, constrained_aba_many), PROXGEN_BATCH_MANY(NS4, prox_pv_many)},          \
        {PROXGEN_BATCH_MANY(NS8, constrained_aba_many), PROXGEN_BATCH_MANY(NS8, prox_pv_many)},          \
        {PROXGEN_BATCH_SCALAR(NSAVX2, constrained_aba), PROXGEN_BATCH_SCALAR(NSAVX2, prox_pv)},          \
        {PROXGEN_BATCH_MANY(NSAVX2, constrained_aba_many), PROXGEN_BATCH_MANY(NSAVX2, prox_pv_many)},    \
  }

const std::vector<BatchEntry>& batchSolvers() {
  static const std::vector<BatchEntry> entries{
#include "batch_entries.inc"
  };
  return entries;
}

namespace {

struct Pool {
  int n = 0;
  std::vector<double> q, v, tau;
};

Pool plainLayout(const BenchCase& c) {
  Pool p;
  p.n = int(c.states.size());
  for (const State& s : c.states) {
    p.q.insert(p.q.end(), s.q.data(), s.q.data() + s.q.size());
    p.v.insert(p.v.end(), s.v.data(), s.v.data() + s.v.size());
    p.tau.insert(p.tau.end(), s.tau.data(), s.tau.data() + s.tau.size());
  }
  return p;
}

struct Out {
  std::vector<double> qdd, lambda;
};

// Largest |batched - scalar| / max(1, |scalar|) over every output.
double largestDifference(const Out& a, const Out& b) {
  double worst = 0;
  const auto one = [&](const std::vector<double>& x, const std::vector<double>& y) {
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double d = std::fabs(x[i] - y[i]) / std::max(1.0, std::fabs(y[i]));
      worst = std::max(worst, std::isnan(d) && !(std::isnan(x[i]) && std::isnan(y[i])) ? INFINITY : d);
    }
  };
  one(a.qdd, b.qdd);
  one(a.lambda, b.lambda);
  return worst;
}

// Pinocchio's algorithm ("pin_caba" or "pin_pv") on the case, called once per
// state of the pool (its solver reads the case's own states: the same
// states as the pool's), or an empty function when the build has no Pinocchio.
PoolSolve pinocchioLoop(const BenchCase& c, const char* algorithm, std::shared_ptr<Solver>& keep) {
  for (const PeerEntry& p : peerSolvers())
    if (std::strcmp(p.algorithm, algorithm) == 0) {
      keep = p.make(c);
      Solver* solver = keep.get();
      return [solver](int n, const double*, const double*, const double*, double*, double*) {
        for (int k = 0; k < n; ++k) solver->solve(k);
      };
    }
  return {};
}

std::string rate(double r) { return r > 0 ? fmt::format("{:.3g}", r) : std::string(); }
std::string ratio(double a, double b) { return a > 0 && b > 0 ? fmt::format("{:.2f}", a / b) : std::string(); }

}  // namespace
}  // namespace proxgen::bench

int main(int argc, char** argv) {
  using namespace proxgen::bench;
  double minTime = 0.3;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--min-time") == 0 && i + 1 < argc) {
      minTime = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--case") == 0 && i + 1 < argc) {
      only.push_back(argv[++i]);
    } else {
      fmt::print(stderr, "usage: proxgen_bench_batch [--min-time SECONDS] [--case NAME]...\n");
      return 2;
    }
  }
#ifdef PROXGEN_BENCH_BATCH_AVX2_FLAGS
  fmt::print("AVX2 variant: W = 4 and its scalar solver compiled with {} after -march\n",
             PROXGEN_BENCH_BATCH_AVX2_FLAGS);
#endif
  fmt::print("| case | solver | scalar states/s | W=4 states/s | W=4 ratio | W=8 states/s | W=8 ratio | "
             "AVX2 scalar states/s | AVX2 W=4 states/s | AVX2 W=4 ratio | Pinocchio loop states/s | "
             "W=4 / Pinocchio | W=8 / Pinocchio | max rel. diff. |\n"
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const BatchEntry& e : batchSolvers()) {
    if (!only.empty() && std::find(only.begin(), only.end(), e.name) == only.end()) continue;
    const BenchCase* found = nullptr;
    for (const BenchCase& c : sharedCases())
      if (c.name == e.name) found = &c;
    if (!found) {
      fmt::print(stderr, "proxgen_bench_batch: no shared case {}\n", e.name);
      return 1;
    }
    const Pool p = plainLayout(*found);
    for (int algorithm = 0; algorithm < 2; ++algorithm) {
      std::shared_ptr<Solver> pinocchio;
      const PoolSolve pin = pinocchioLoop(*found, algorithm == 0 ? "pin_caba" : "pin_pv", pinocchio);
      // 0 scalar, 1 W = 4, 2 W = 8, 3 AVX2 scalar, 4 AVX2 W = 4, 5 Pinocchio (each may be empty).
      const PoolSolve* solves[6] = {&e.scalar[algorithm],     &e.batch4[algorithm],     &e.batch8[algorithm],
                                    &e.scalarAvx2[algorithm], &e.batch4Avx2[algorithm], &pin};
      constexpr int kVariants = 6;
      int present = 0;
      for (const PoolSolve* f : solves) present += *f ? 1 : 0;
      Out out[kVariants];
      double best[kVariants];
      std::fill(best, best + kVariants, INFINITY);
      for (Out& o : out) o = {std::vector<double>(std::size_t(p.n * e.nv)), std::vector<double>(std::size_t(p.n * e.nc + 1))};
      double elapsed = 0;
      while (elapsed < minTime * present) {
        for (int j = 0; j < kVariants; ++j) {
          if (!*solves[j]) continue;
          const auto t0 = std::chrono::steady_clock::now();
          (*solves[j])(p.n, p.q.data(), p.v.data(), p.tau.data(), out[j].qdd.data(), out[j].lambda.data());
          const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          best[j] = std::min(best[j], t);
          elapsed += t;
        }
      }
      double r[kVariants];
      for (int j = 0; j < kVariants; ++j) r[j] = *solves[j] ? p.n / best[j] : 0;
      double diff = std::max(largestDifference(out[1], out[0]), largestDifference(out[2], out[0]));
      if (*solves[4]) diff = std::max(diff, largestDifference(out[4], out[3]));
      fmt::print("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1e} |\n", e.name,
                 algorithm == 0 ? "constrained_aba" : "prox_pv", rate(r[0]), rate(r[1]), ratio(r[1], r[0]), rate(r[2]),
                 ratio(r[2], r[0]), rate(r[3]), rate(r[4]), ratio(r[4], r[3]), rate(r[5]), ratio(r[1], r[5]),
                 ratio(r[2], r[5]), diff);
      std::fflush(stdout);
    }
  }
  return 0;
}

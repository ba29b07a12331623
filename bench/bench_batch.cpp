// States per second per core of the batched generated solvers (generate
// --batch W, docs/batch.md) against the scalar generated solver, in the same
// run, on each shared case's state pool (common.hpp: 1000 random states,
// K = 3, mu = 1e4). Each variant solves the whole pool (scalar: a loop of
// single calls; batched: one _many call), repeated until 0.3 s have passed,
// best pass kept; the variants alternate so that frequency drift hits all.
// It also prints the largest difference of each batched answer from the
// scalar one (0 unless the compiler fused multiply-adds differently in the
// two, -ffp-contract: docs/batch.md, "Lane by lane").
//   proxgen_bench_batch [--min-time SECONDS]    (bench/RESULTS.md, "Batched solvers")
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "common.hpp"
// The generated solvers (bench/CMakeLists.txt, PROXGEN_BENCH_BATCH_CASES): their headers.
#include "batch_includes.inc"

namespace proxgen::bench {

// n states in the plain layout: state k's q at q + k * nq, and so on.
using PoolSolve = std::function<void(int n, const double* q, const double* v, const double* tau, double* qdd,
                                     double* lambda)>;

struct BatchEntry {
  const char* name;
  int nq, nv, nc;
  PoolSolve scalarCaba, scalarPv, caba4, pv4, caba8, pv8;
};

template <class Settings>
Settings benchSettings() {
  Settings s;
  s.mu = kMu;
  s.iterations = kIterations;
  return s;
}

// The scalar solver in a loop, and the two batched _many functions, of the
// solvers generated with BATCH 4 (NS4) and BATCH 8 (NS8).
#define PROXGEN_BATCH_ENTRY(CASE, NS4, NS8)                                                                   \
  BatchEntry {                                                                                                \
    CASE, NS4::nq, NS4::nv, NS4::nc,                                                                          \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS4::Workspace w;                                                                            \
          const auto s = benchSettings<NS4::Settings>();                                                      \
          for (int k = 0; k < n; ++k)                                                                         \
            NS4::constrained_aba(q + k * NS4::nq, v + k * NS4::nv, tau + k * NS4::nv, s, w, qdd + k * NS4::nv, \
                                 lambda + k * NS4::nc);                                                       \
        },                                                                                                    \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS4::Workspace w;                                                                            \
          const auto s = benchSettings<NS4::Settings>();                                                      \
          for (int k = 0; k < n; ++k)                                                                         \
            NS4::prox_pv(q + k * NS4::nq, v + k * NS4::nv, tau + k * NS4::nv, s, w, qdd + k * NS4::nv,         \
                         lambda + k * NS4::nc);                                                               \
        },                                                                                                    \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS4::BatchWorkspace w;                                                                       \
          NS4::constrained_aba_many(n, q, v, tau, benchSettings<NS4::Settings>(), w, qdd, lambda);            \
        },                                                                                                    \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS4::BatchWorkspace w;                                                                       \
          NS4::prox_pv_many(n, q, v, tau, benchSettings<NS4::Settings>(), w, qdd, lambda);                    \
        },                                                                                                    \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS8::BatchWorkspace w;                                                                       \
          NS8::constrained_aba_many(n, q, v, tau, benchSettings<NS8::Settings>(), w, qdd, lambda);            \
        },                                                                                                    \
        [](int n, const double* q, const double* v, const double* tau, double* qdd, double* lambda) {         \
          static NS8::BatchWorkspace w;                                                                       \
          NS8::prox_pv_many(n, q, v, tau, benchSettings<NS8::Settings>(), w, qdd, lambda);                    \
        },                                                                                                    \
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

}  // namespace
}  // namespace proxgen::bench

int main(int argc, char** argv) {
  using namespace proxgen::bench;
  double minTime = 0.3;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--min-time") == 0 && i + 1 < argc) {
      minTime = std::atof(argv[++i]);
    } else {
      fmt::print(stderr, "usage: proxgen_bench_batch [--min-time SECONDS]\n");
      return 2;
    }
  }
  fmt::print("| case | solver | scalar states/s | W=4 states/s | W=4 ratio | W=8 states/s | W=8 ratio | "
             "max rel. diff. |\n|---|---|---:|---:|---:|---:|---:|---:|\n");
  for (const BatchEntry& e : batchSolvers()) {
    const BenchCase* found = nullptr;
    for (const BenchCase& c : sharedCases())
      if (c.name == e.name) found = &c;
    if (!found) {
      fmt::print(stderr, "proxgen_bench_batch: no shared case {}\n", e.name);
      return 1;
    }
    const Pool p = plainLayout(*found);
    for (int algorithm = 0; algorithm < 2; ++algorithm) {
      const PoolSolve* solves[3] = {algorithm == 0 ? &e.scalarCaba : &e.scalarPv, algorithm == 0 ? &e.caba4 : &e.pv4,
                                    algorithm == 0 ? &e.caba8 : &e.pv8};
      Out out[3];
      double best[3] = {INFINITY, INFINITY, INFINITY};
      for (Out& o : out) o = {std::vector<double>(std::size_t(p.n * e.nv)), std::vector<double>(std::size_t(p.n * e.nc + 1))};
      double elapsed = 0;
      while (elapsed < minTime * 3) {
        for (int j = 0; j < 3; ++j) {
          const auto t0 = std::chrono::steady_clock::now();
          (*solves[j])(p.n, p.q.data(), p.v.data(), p.tau.data(), out[j].qdd.data(), out[j].lambda.data());
          const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          best[j] = std::min(best[j], t);
          elapsed += t;
        }
      }
      const double rate[3] = {p.n / best[0], p.n / best[1], p.n / best[2]};
      const double diff = std::max(largestDifference(out[1], out[0]), largestDifference(out[2], out[0]));
      fmt::print("| {} | {} | {:.3g} | {:.3g} | {:.2f} | {:.3g} | {:.2f} | {:.1e} |\n", e.name,
                 algorithm == 0 ? "constrained_aba" : "prox_pv", rate[0], rate[1], rate[1] / rate[0], rate[2],
                 rate[2] / rate[0], diff);
    }
  }
  return 0;
}

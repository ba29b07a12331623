// proxgen_bench_calls CASE ALGORITHM N: N calls of one solver, cycling the
// case's state pool, for instruction counts under callgrind. Everything but the
// N calls (loading, states, work space) is the same for every N, so
// (Ir(N) - Ir(0)) / N is the cost of one call.
// Exit codes: 0 done, 1 error, 3 the algorithm is not built (generated solvers off).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>

#include "common.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s CASE ALGORITHM N\n", argv[0]);
    return 1;
  }
  try {
    const proxgen::bench::BenchCase c = proxgen::bench::loadSharedCase(argv[1]);
    std::unique_ptr<proxgen::bench::Solver> solver = proxgen::bench::makeSolver(c, argv[2]);
    if (!solver) {
      std::fprintf(stderr, "proxgen_bench_calls: %s is not built (PROXGEN_BENCH_GENERATED)\n", argv[2]);
      return 3;
    }
    const long n = std::stol(argv[3]);
    const int states = int(c.states.size());
    int k = 0;
    for (long call = 0; call < n; ++call) {
      solver->solve(k);
      benchmark::DoNotOptimize(solver->output());
      benchmark::ClobberMemory();
      if (++k == states) k = 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "proxgen_bench_calls: %s\n", e.what());
    return 1;
  }
  return 0;
}

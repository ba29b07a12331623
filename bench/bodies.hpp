// The benchmark bodies of bench_joint_space.cpp and bench_derivatives.cpp: one
// call of one variant on state k, registered by name ("case/function/variant"),
// then either timed by Google Benchmark (the states cycled in the timed loop)
// or, with `--count NAME N`, called N times for callgrind (bench/count_calls.py:
// the run with N = 0 is the baseline, so everything but the N calls must be the
// same for every N).
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace proxgen::bench {

struct Body {
  std::string name;
  int states, nv, nc;
  std::function<void(int)> call;
  std::vector<std::pair<std::string, double>> counters;  // reported beside the time
};

inline std::vector<Body>& bodies() {
  static std::vector<Body> b;
  return b;
}

inline void timedBody(benchmark::State& st, const Body* b) {
  int k = 0;
  for (auto _ : st) {
    b->call(k);
    benchmark::ClobberMemory();
    if (++k == b->states) k = 0;
  }
  st.counters["nv"] = b->nv;
  st.counters["nc"] = b->nc;
  for (const auto& [key, value] : b->counters) st.counters[key] = value;
}

/// --count: n calls of the body `name` (exit code 0), or 3 when this build has none.
inline int countBody(const char* program, const std::string& name, long n) {
  for (const Body& b : bodies()) {
    if (b.name != name) continue;
    int k = 0;
    for (long call = 0; call < n; ++call) {
      b.call(k);
      benchmark::ClobberMemory();
      if (++k == b.states) k = 0;
    }
    return 0;
  }
  std::fprintf(stderr, "%s: no benchmark %s in this build\n", program, name.c_str());
  return 3;
}

/// Every body as a benchmark (microseconds), then Google Benchmark's own flags and run.
inline int runBodies(int argc, char** argv) {
  for (const Body& b : bodies())
    benchmark::RegisterBenchmark(b.name.c_str(), timedBody, &b)->Unit(benchmark::kMicrosecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace proxgen::bench

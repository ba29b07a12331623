// Google Benchmark suite over the shared cases (cases.yaml): every algorithm of
// algorithmNames() that this build has, named <case>/<algorithm>, with the case's
// DoF and constraint rows as counters. States are drawn before any timing and
// cycled inside the timed loop.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <vector>

#include "common.hpp"

namespace {

using proxgen::bench::Solver;

void run(benchmark::State& st, Solver* solver, int states, int nv, int nc) {
  int k = 0;
  for (auto _ : st) {
    solver->solve(k);
    benchmark::DoNotOptimize(solver->output());
    benchmark::ClobberMemory();
    if (++k == states) k = 0;
  }
  st.counters["nv"] = nv;
  st.counters["nc"] = nc;
  for (const auto& [name, value] : solver->counters()) st.counters[name] = value;
}

// The fastest repetition, beside Google Benchmark's median: on a shared VM the
// medians carry the other tenants' load, the minima repeat within a few percent
// (docs/benchmarks.md, "Emitted code").
double minimum(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end()); }

// Solvers live for the whole run so that the timing never includes set-up.
std::vector<std::unique_ptr<Solver>>& solvers() {
  static std::vector<std::unique_ptr<Solver>> s;
  return s;
}

void registerAll() {
  for (const auto& c : proxgen::bench::sharedCases()) {
    for (const std::string& algorithm : proxgen::bench::algorithmNames()) {
      std::unique_ptr<Solver> s = proxgen::bench::makeSolver(c, algorithm);
      if (!s) continue;  // generated solvers not built
      benchmark::RegisterBenchmark((c.name + "/" + algorithm).c_str(), run, s.get(), int(c.states.size()),
                                   c.sys.model.nv, c.sys.nc)
          ->Unit(benchmark::kMicrosecond)
          ->ComputeStatistics("min", minimum);
      solvers().push_back(std::move(s));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  try {
    registerAll();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "proxgen_bench: %s\n", e.what());
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

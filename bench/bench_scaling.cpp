// Scaling study on synthetic robots (synthetic.hpp): generic constrainedABA and
// proxPV timed against the DoF n at a fixed number of contact rows, and against
// the rows m at a fixed n, for a serial chain and a binary tree. The URDFs and
// layouts are written into --out DIR (default: ./scaling-models) and loaded by
// the library like any robot. Benchmarks are named <shape>/n:<n>/m:<m>/<algorithm>.
//
//   proxgen_bench_scaling [--out DIR] [--quick] [Google Benchmark flags]
// --quick: two sizes per sweep (the smoke test).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "model/layout.hpp"
#include "synthetic.hpp"

namespace {

using namespace proxgen;
using namespace proxgen::bench;

// The n sweep holds the contacts at kFixedContacts (m = 6); the m sweeps hold n at
// 128, where the O(n) part dominates, and at 32, where the rows' O(m^2 d + m^3) part shows.
// At n = 128 the m sweep goes on past 40 rows (to 192) so that the m^3 term can show.
constexpr int kFixedContacts = 2;

struct Problem {
  System sys;
  std::vector<State> states;
  std::unique_ptr<Solver> solver;
};

// Problems live for the whole run (solvers keep references to them).
std::vector<std::unique_ptr<Problem>>& problems() {
  static std::vector<std::unique_ptr<Problem>> p;
  return p;
}

void run(benchmark::State& st, Solver* solver, int states, int n, int m) {
  int k = 0;
  for (auto _ : st) {
    solver->solve(k);
    benchmark::DoNotOptimize(solver->output());
    benchmark::ClobberMemory();
    if (++k == states) k = 0;
  }
  st.counters["n"] = n;
  st.counters["m"] = m;
}

void add(const std::string& dir, Shape shape, int n, int contacts) {
  std::string urdf, layout;
  writeSynthetic(dir, shape, n, contacts, urdf, layout);
  for (const char* algorithm : {"caba", "pv"}) {
    auto p = std::make_unique<Problem>();
    p->sys = loadSystem(urdf, layout);
    p->states = statePool(p->sys.model, unsigned(n * 100 + contacts));
    p->solver = makeGenericSolver(p->sys, p->states, algorithm);
    const std::string name = std::string(shapeName(shape)) + "/n:" + std::to_string(n) + "/m:" +
                             std::to_string(p->sys.nc) + "/" + algorithm;
    benchmark::RegisterBenchmark(name.c_str(), run, p->solver.get(), int(p->states.size()), p->sys.model.nv,
                                 p->sys.nc)
        ->Unit(benchmark::kMicrosecond);
    problems().push_back(std::move(p));
  }
}

void registerAll(const std::string& dir, bool quick) {
  const std::vector<int> dofs = quick ? std::vector<int>{8, 16} : std::vector<int>{8, 16, 32, 64, 128, 256, 512};
  // 3 rows per contact: m = 3, 6, 12, 18, 24, 30, 39 (40 itself is not a multiple of 3).
  const std::vector<int> contacts = quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 4, 6, 8, 10, 13};
  const std::vector<int> fixedDofs = quick ? std::vector<int>{16} : std::vector<int>{32, 128};
  for (Shape shape : {Shape::Chain, Shape::Tree}) {
    std::set<std::pair<int, int>> done;
    for (int n : dofs)
      if (done.insert({n, kFixedContacts}).second) add(dir, shape, n, kFixedContacts);
    for (int n : fixedDofs)
      for (int c : contacts)
        if (done.insert({n, c}).second) add(dir, shape, n, c);
    if (!quick)
      for (int c : {20, 32, 48, 64})
        if (done.insert({128, c}).second) add(dir, shape, 128, c);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::string dir = "scaling-models";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      dir = argv[++i];
    } else {
      std::fprintf(stderr, "proxgen_bench_scaling: unknown argument %s\n", argv[i]);
      return 1;
    }
  }
  try {
    registerAll(dir, quick);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "proxgen_bench_scaling: %s\n", e.what());
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// One synthetic robot's generated delassus_inverse, timed or counted
// (bench/delassus_scaling.py compiles this once per model with
// -DPROXGEN_SCALING_HEADER="<ns>.hpp" -DPROXGEN_SCALING_NS=<ns>).
//
//   driver time REPETITIONS   median and minimum CPU µs per call over REPETITIONS
//                             batches of ~20 ms, as JSON on stdout
//   driver count N            N calls and nothing else (callgrind: (Ir(N) - Ir(0)) / N)
//
// CPU time, as the suite's. The synthetic robots have a fixed base and revolute joints (bench/synthetic.hpp),
// so q is nv angles; 64 random configurations are cycled, mu = 1e4.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include PROXGEN_SCALING_HEADER

namespace gen = PROXGEN_SCALING_NS;

namespace {

constexpr int kStates = 64;

// CPU seconds of this process (as Google Benchmark reports): other tenants of a
// shared machine slow it less than the wall clock.
double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Run {
  std::vector<gen::Scalar> q;
  std::vector<gen::Scalar> Ginv;
  gen::Settings s;
  gen::Workspace w;
  int k = 0;
  void call() {
    gen::delassus_inverse(q.data() + std::size_t(k) * gen::nq, s, w, Ginv.data());
    // Keep the answer observable: the compiler may not drop the call.
    asm volatile("" : : "r"(Ginv.data()) : "memory");
    if (++k == kStates) k = 0;
  }
};

}  // namespace

int main(int argc, char** argv) {
  static_assert(gen::nq == gen::nv, "the synthetic robots have a fixed base and revolute joints");
  if (argc != 3 || (std::strcmp(argv[1], "time") != 0 && std::strcmp(argv[1], "count") != 0)) {
    std::fprintf(stderr, "usage: %s time REPETITIONS | count N\n", argv[0]);
    return 1;
  }
  static Run r;  // the workspace can be large: not on the stack
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
  for (int i = 0; i < kStates * gen::nq; ++i) r.q.push_back(gen::Scalar(angle(rng)));
  r.Ginv.resize(std::size_t(gen::nc * gen::nc));
  r.s.mu = gen::Scalar(1e4);
  const long n = std::stol(argv[2]);
  if (argv[1][0] == 'c') {
    for (long i = 0; i < n; ++i) r.call();
    return 0;
  }
  // Calls per batch: about 20 ms, from a first estimate.
  long batch = 16;
  for (;;) {
    const double t0 = cpuSeconds();
    for (long i = 0; i < batch; ++i) r.call();
    const double s = cpuSeconds() - t0;
    if (s > 0.005) {
      batch = std::max(16L, long(double(batch) * 0.02 / s));
      break;
    }
    batch *= 4;
  }
  std::vector<double> us;
  for (long rep = 0; rep < n; ++rep) {
    const double t0 = cpuSeconds();
    for (long i = 0; i < batch; ++i) r.call();
    us.push_back(1e6 * (cpuSeconds() - t0) / double(batch));
  }
  std::sort(us.begin(), us.end());
  std::printf("{\"nv\": %d, \"nc\": %d, \"median_us\": %.6g, \"min_us\": %.6g, \"repetitions\": %ld, \"batch\": %ld}\n",
              gen::nv, gen::nc, us[us.size() / 2], us.front(), n, batch);
  return 0;
}

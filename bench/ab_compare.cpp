// One generated function from two generations of the same case, A and B (two
// proxgen builds, or one build's source compiled with two sets of flags),
// linked side by side: are their outputs the same bit for bit, and what does
// each cost? Driven by bench/ab_compare.sh, which generates the sources under
// the namespaces A and B and defines CALL, the call of the function under test
// (reading q, v, a, lam, s, w and writing o[0], o[1], ...).
//
//   ab_compare check           the states on which any output differs in any bit, and
//                              the largest difference relative to max(1, |entry|)
//   ab_compare time N          A and B alternately (which goes first alternates too),
//                              21 repetitions of N calls each:
//                              median and fastest repetition, and B / A
//   ab_compare count A|B N     N calls of one side (callgrind: (Ir(2N) - Ir(N)) / N)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "A.hpp"
#include "B.hpp"

namespace {

constexpr int nq = A::nq, nv = A::nv, nc = A::nc;
static_assert(nq == B::nq && nv == B::nv && nc == B::nc, "A and B are not the same robot and layout");
constexpr int kStates = 1000, kOutputs = 8, kOutputSize = (nv + nc) * (nv + nc);

struct States {
  std::vector<double> q, v, a, lam;
  States() : q(kStates * nq), v(kStates * nv), a(kStates * nv), lam(kStates * (nc > 0 ? nc : 1)) {
    std::mt19937 g(1);
    std::normal_distribution<double> d(0, 1);
    for (std::vector<double>* x : {&q, &v, &a, &lam})
      for (double& y : *x) y = d(g);
  }
};

// One side: its workspace, settings and output buffers.
template <class Workspace, class Settings>
struct Side {
  Workspace w{};
  Settings s{};
  std::vector<std::vector<double>> out{kOutputs, std::vector<double>(kOutputSize, 0.0)};
  double* o[kOutputs];
  Side() {
    for (int k = 0; k < kOutputs; ++k) o[k] = out[std::size_t(k)].data();
  }
};

Side<A::Workspace, A::Settings>& sideA() {
  static Side<A::Workspace, A::Settings> x;
  return x;
}
Side<B::Workspace, B::Settings>& sideB() {
  static Side<B::Workspace, B::Settings> x;
  return x;
}

// State n's inputs and one call of the function on a side (CALL finds the
// side's namespace through its Workspace argument).
template <class SideT>
void call(const States& st, int n, SideT& side) {
  const int k = n % kStates;
  const double* q = &st.q[std::size_t(k * nq)];
  const double* v = &st.v[std::size_t(k * nv)];
  const double* a = &st.a[std::size_t(k * nv)];
  const double* lam = &st.lam[std::size_t(k * (nc > 0 ? nc : 1))];
  auto& w = side.w;
  auto& s = side.s;
  double* const* o = side.o;
  static_cast<void>(q), static_cast<void>(v), static_cast<void>(a), static_cast<void>(lam), static_cast<void>(s);
  CALL;
}

template <class SideT>
double seconds(const States& st, int calls, SideT& side) {
  const auto t0 = std::chrono::steady_clock::now();
  for (int n = 0; n < calls; ++n) call(st, n, side);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int usage() {
  std::fprintf(stderr, "usage: ab_compare check | time N | count A|B N\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const States st;
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "check" && argc == 2) {
    int differ = 0;
    long written = 0;   // nonzero output entries of A, over all states
    double worst = 0;   // the largest |a - b| / max(1, |a|) over every entry
    for (int n = 0; n < kStates; ++n) {
      call(st, n, sideA());
      call(st, n, sideB());
      bool same = true;
      for (int k = 0; k < kOutputs; ++k) {
        same &= std::memcmp(sideA().o[k], sideB().o[k], sizeof(double) * kOutputSize) == 0;
        for (int j = 0; j < kOutputSize; ++j) {
          const double a = sideA().o[k][j], b = sideB().o[k][j];
          written += a != 0.0;
          worst = std::max(worst, std::abs(a - b) / std::max(1.0, std::abs(a)));
        }
      }
      differ += same ? 0 : 1;
    }
    std::printf("states whose outputs differ in any bit: %d of %d; largest |A - B| / max(1, |A|): %.3g\n", differ,
                kStates, worst);
    // Outputs that stay zero would agree whatever the code: a comparison of nothing.
    if (written == 0) {
      std::fprintf(stderr, "ab_compare: the function wrote no nonzero output: nothing was compared\n");
      return 1;
    }
    return 0;
  }
  if (mode == "time" && argc == 3) {
    const int calls = std::atoi(argv[2]);
    if (calls <= 0) return usage();
    std::vector<double> ta, tb;
    for (int rep = 0; rep < 21; ++rep) {  // A first in even repetitions, B first in odd ones
      if (rep % 2 == 1) tb.push_back(seconds(st, calls, sideB()) / calls * 1e6);
      ta.push_back(seconds(st, calls, sideA()) / calls * 1e6);
      if (rep % 2 == 0) tb.push_back(seconds(st, calls, sideB()) / calls * 1e6);
    }
    std::sort(ta.begin(), ta.end());
    std::sort(tb.begin(), tb.end());
    std::printf("A: median %.4g us, fastest %.4g us; B: median %.4g us, fastest %.4g us; B / A: median %.3f, fastest %.3f\n",
                ta[10], ta[0], tb[10], tb[0], tb[10] / ta[10], tb[0] / ta[0]);
    return 0;
  }
  if (mode == "count" && argc == 4) {
    const std::string which = argv[2];
    const int calls = std::atoi(argv[3]);
    if (calls < 0 || (which != "A" && which != "B")) return usage();
    if (which == "A") seconds(st, calls, sideA());
    else seconds(st, calls, sideB());
    return 0;
  }
  return usage();
}

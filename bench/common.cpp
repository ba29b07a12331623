#include "common.hpp"

#include <algorithm>
#include <random>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/prox_ltl.hpp"
#include "algorithms/prox_ltls.hpp"
#include "algorithms/prox_pv.hpp"
#include "generated.hpp"
#include "cases/cases.hpp"
#include "model/error.hpp"

namespace proxgen::bench {

std::vector<State> statePool(const Model& model, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<State> states;
  states.reserve(kStates);
  for (int k = 0; k < kStates; ++k) states.push_back(randomState(model, rng));
  return states;
}

namespace {

// Case k of cases.yaml draws its states from seed k + 1, whichever way it was loaded.
BenchCase loadBenchCase(const Case& c, unsigned index) {
  System sys = loadCaseSystem(c);
  std::vector<State> states = statePool(sys.model, index + 1);
  return BenchCase{c.name, std::move(sys), std::move(states)};
}

}  // namespace

const std::vector<BenchCase>& sharedCases() {
  static const std::vector<BenchCase> cases = [] {
    std::vector<BenchCase> out;
    const std::vector<Case> all = loadCases(PROXGEN_BENCH_CASES_FILE);
    for (std::size_t k = 0; k < all.size(); ++k) out.push_back(loadBenchCase(all[k], unsigned(k)));
    return out;
  }();
  return cases;
}

BenchCase loadSharedCase(const std::string& name) {
  const std::vector<Case> all = loadCases(PROXGEN_BENCH_CASES_FILE);
  for (std::size_t k = 0; k < all.size(); ++k)
    if (all[k].name == name) return loadBenchCase(all[k], unsigned(k));
  throw Error("no case " + quoted(name) + " in " PROXGEN_BENCH_CASES_FILE);
}

const std::vector<std::string>& algorithmNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out{"aba", "caba", "pv", "ltl", "ltls", "gen_caba", "gen_pv"};
    for (const PeerEntry& p : peerSolvers()) out.emplace_back(p.algorithm);
    return out;
  }();
  return names;
}

bool isGenerated(const std::string& algorithm) { return algorithm.rfind("gen_", 0) == 0; }

namespace {

using GenericFn = void (*)(const System&, Data&, const State&);

void runAba(const System& sys, Data& d, const State& s) { aba(sys, d, s.q, s.v, s.tau); }
void runCaba(const System& sys, Data& d, const State& s) { constrainedAba(sys, d, s.q, s.v, s.tau, kMu, kIterations); }
void runPv(const System& sys, Data& d, const State& s) { proxPv(sys, d, s.q, s.v, s.tau, kMu, kIterations); }
void runLtl(const System& sys, Data& d, const State& s) { proxLtl(sys, d, s.q, s.v, s.tau, kMu, kIterations); }
void runLtls(const System& sys, Data& d, const State& s) { proxLtls(sys, d, s.q, s.v, s.tau, kMu, kIterations); }

[[noreturn]] void unknownAlgorithm(const std::string& algorithm) {
  throw Error("unknown algorithm " + quoted(algorithm) + " (aba, caba, pv, ltl, ltls, gen_caba, gen_pv)");
}

GenericFn genericFunction(const std::string& algorithm) {
  if (algorithm == "aba") return runAba;
  if (algorithm == "caba") return runCaba;
  if (algorithm == "pv") return runPv;
  if (algorithm == "ltl") return runLtl;
  if (algorithm == "ltls") return runLtls;
  unknownAlgorithm(algorithm);
}

// Every generic algorithm writes d.qdd; the Data is built once, outside the timing.
class GenericSolver final : public Solver {
 public:
  GenericSolver(const System& sys, const std::vector<State>& states, GenericFn fn)
      : sys_(sys), states_(states), fn_(fn), d_(sys) {}
  void solve(int k) override { fn_(sys_, d_, states_[std::size_t(k)]); }
  const void* output() const override { return d_.qdd.data(); }

 private:
  const System& sys_;
  const std::vector<State>& states_;
  GenericFn fn_;
  Data d_;
};

}  // namespace

std::unique_ptr<Solver> makeGenericSolver(const System& sys, const std::vector<State>& states,
                                          const std::string& algorithm) {
  return std::make_unique<GenericSolver>(sys, states, genericFunction(algorithm));
}

std::unique_ptr<Solver> makeSolver(const BenchCase& c, const std::string& algorithm) {
  for (const PeerEntry& p : peerSolvers())
    if (algorithm == p.algorithm) return p.make(c);
  if (!isGenerated(algorithm)) return makeGenericSolver(c.sys, c.states, algorithm);
  if (algorithm != "gen_caba" && algorithm != "gen_pv") unknownAlgorithm(algorithm);
  for (const GeneratedEntry& e : generatedSolvers())
    if (c.name == e.caseName) return (algorithm == "gen_caba" ? e.caba : e.pv)(c);
  return nullptr;
}

}  // namespace proxgen::bench

// What the benchmark executables share: the cases, a pool of random states per
// case drawn once outside any timed region, and one `Solver` per (case,
// algorithm) that runs a single call on state k of its pool.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "model/model.hpp"
#include "model/state.hpp"

namespace proxgen::bench {

// The solver settings of every benchmark (docs/benchmarks.md, "Anchor figures": K = 3, mu = 1e4).
inline constexpr int kIterations = 3;
inline constexpr double kMu = 1e4;
// As many states as the Pinocchio anchor cycled through, so both read the same
// amount of input per call.
inline constexpr int kStates = 1000;

/// A robot and layout with its state pool.
struct BenchCase {
  std::string name;
  System sys;
  std::vector<State> states;
};

/// `kStates` random states from a fixed seed: the same pool in every process, so
/// the callgrind runs with N and with 0 calls differ only by the calls.
std::vector<State> statePool(const Model& model, unsigned seed);

/// The cases of cases.yaml (the path the build recorded), loaded once.
const std::vector<BenchCase>& sharedCases();
/// One case alone (same states as in sharedCases()), for the callgrind driver.
BenchCase loadSharedCase(const std::string& name);

/// One algorithm bound to one case, with its preallocated work space.
class Solver {
 public:
  virtual ~Solver() = default;
  /// One call on state k of the case's pool.
  virtual void solve(int k) = 0;
  /// The joint accelerations of the last call (kept alive by the caller).
  virtual const void* output() const = 0;
  /// Figures the suite reports beside the time (a peer's agreement with the generic
  /// solvers, its solver iterations); none by default.
  virtual std::vector<std::pair<std::string, double>> counters() const { return {}; }
};

/// A peer: another library's solver on the same case and states (bench_mujoco.cpp,
/// bench_pinocchio.cpp), compiled in only where CMake finds the library.
struct PeerEntry {
  const char* algorithm;
  std::unique_ptr<Solver> (*make)(const BenchCase&);
};
/// The peers of this build (peer_solvers.cpp, written by bench/CMakeLists.txt).
const std::vector<PeerEntry>& peerSolvers();

/// The algorithms, in table order. Generic: aba, caba, pv, ltl, ltls; generated:
/// gen_caba, gen_pv; then the peers this build has (mujoco, pin_caba, pin_pv).
const std::vector<std::string>& algorithmNames();
bool isGenerated(const std::string& algorithm);

/// A solver for (case, algorithm), or nullptr when the algorithm is not built
/// (generated solvers with PROXGEN_BENCH_GENERATED off). Throws proxgen::Error
/// for an unknown algorithm.
std::unique_ptr<Solver> makeSolver(const BenchCase& c, const std::string& algorithm);

/// A generic solver on any System and state pool (the scaling study uses it).
std::unique_ptr<Solver> makeGenericSolver(const System& sys, const std::vector<State>& states,
                                          const std::string& algorithm);

}  // namespace proxgen::bench

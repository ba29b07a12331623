// Shared test helpers: where the shared models are, random states, norms.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "cases/cases.hpp"
#include "model/error.hpp"
#include "model/model.hpp"
#include "model/state.hpp"

namespace proxgen::test {

/// True in a build instrumented by AddressSanitizer (scripts/sanitize.sh):
/// tests that assert time or memory skip there, where both mean nothing.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderSanitizer = true;
#else
inline constexpr bool kUnderSanitizer = false;
#endif
#else
inline constexpr bool kUnderSanitizer = false;
#endif
#define PROXGEN_SKIP_UNDER_SANITIZER()                                                       \
  do {                                                                                       \
    if (::proxgen::test::kUnderSanitizer)                                                    \
      GTEST_SKIP() << "time and memory of an instrumented build mean nothing";              \
  } while (0)

/// The shared models folder (CMake cache PROXGEN_MODELS_DIR), or "" if absent.
std::string modelsDir();
bool underCi();

/// Skips the test (fails under CI=true) when the shared models are missing.
#define PROXGEN_REQUIRE_MODELS()                                                                   \
  do {                                                                                             \
    if (::proxgen::test::modelsDir().empty()) {                                                    \
      if (::proxgen::test::underCi()) FAIL() << "shared models folder missing (PROXGEN_MODELS_DIR)"; \
      GTEST_SKIP() << "needs the shared models folder: configure with -DPROXGEN_MODELS_DIR=...";  \
    }                                                                                              \
  } while (0)

/// The nine cases of cases.yaml (empty when the models are missing).
std::vector<Case> sharedCases();
/// A robot and layout under the name the tests report.
struct NamedSystem {
  std::string name;
  System sys;
};
/// Every shared case, then the repository's robots the generic library and
/// derivative suites also run on: the three examples, the example quadruped
/// with Baumgarte gains (a* != 0), the analytic floating arm with gains and
/// with two welds on one link (rank 6 of 12 rows), and four coplanar contacts
/// on a box (12 rows on 6 dofs). Each suite appends its own.
std::vector<NamedSystem> sharedAndRepositorySystems();
/// Path of a file in the shared models folder.
std::string modelPath(const std::string& file);

/// A random state (proxgen::randomState: inside joint limits, random unit quaternion).
using RandomState = State;
inline RandomState randomState(const Model& m, std::mt19937& rng) { return proxgen::randomState(m, rng); }

/// max |a - b| / max(1, max |b|): relative to the size of the reference vector.
double relErr(const VecX& a, const VecX& b);

/// The repository's root (for generated/ and tests/data).
std::string sourceDir();

/// A synthetic robot of `links` links: link i (1 kg, 0.1 m from its parent,
/// revolute about x, y, z in turn) hangs from link (i - 1) / branching, so
/// branching 1 is a chain; `pad` goes inside <robot> after the tree. The same
/// robots as tests/data/hostile/make_big_urdf.py writes to files.
std::string syntheticTreeUrdf(int links, int branching, const std::string& pad = "");

/// The generated files of syntheticTreeUrdf(links, 1) on a fixed base (a chain
/// of links - 1 revolute joints), named "chain", holding `functions` (--functions;
/// "" = the two solvers); `constraints`: the layout's constraints list (YAML
/// flow items, "- {name: tip, link: l11, type: 3d}"), none when empty.
emit::SolverFiles syntheticChainFiles(int links, const std::string& functions = "", const std::string& constraints = "");

/// How many times `what` occurs in `text`, without overlaps (generated code's shape tests).
long occurrences(const std::string& text, const std::string& what);

// --- files and child processes (the tests that run the `proxgen` binary) -----

/// The whole file as bytes ("" when it cannot be read).
std::string slurp(const std::filesystem::path& p);

/// `s` in single quotes for /bin/sh, embedded quotes escaped.
std::string shellQuoted(const std::string& s);

/// How a child process ended and what it printed.
struct ProcessResult {
  int code = -1;  // exit status, -1 if it did not exit normally
  std::string out, err;
};

/// Runs `program args...` through /bin/sh, stdout and stderr captured in
/// temporary files (removed afterwards). Every argument is shell-quoted.
ProcessResult runProgram(const std::string& program, const std::vector<std::string>& args);

/// A file in the temporary folder, unique to this process and object (the name
/// ends in `suffix`), removed when the object goes.
class TempFile {
 public:
  explicit TempFile(const std::string& suffix);
  ~TempFile();
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }
  /// Writes `text` (bytes as given); returns the path.
  const std::string& write(const std::string& text) const;
  /// A sparse file of `bytes` bytes, for size limits; returns the path.
  const std::string& sized(std::uintmax_t bytes) const;

 private:
  std::string path_;
};

/// The message of the proxgen::Error that `load` must throw ("" otherwise, with a failure).
template <class Load>
std::string errorOf(Load&& load) {
  try {
    load();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw something other than proxgen::Error: " << e.what();
    return "";
  }
  ADD_FAILURE() << "accepted the input";
  return "";
}

}  // namespace proxgen::test

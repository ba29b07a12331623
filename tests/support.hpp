// Shared test helpers: where the shared models are, random states, norms.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "model/cases.hpp"
#include "model/model.hpp"
#include "model/state.hpp"

namespace proxgen::test {

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
/// Path of a file in the shared models folder.
std::string modelPath(const std::string& file);

/// A random state (proxgen::randomState: inside joint limits, random unit quaternion).
using RandomState = State;
inline RandomState randomState(const Model& m, std::mt19937& rng) { return proxgen::randomState(m, rng); }

/// max |a - b| / max(1, max |b|): relative to the size of the reference vector.
double relErr(const VecX& a, const VecX& b);

/// The repository's root (for generated/ and tests/data).
std::string sourceDir();

}  // namespace proxgen::test

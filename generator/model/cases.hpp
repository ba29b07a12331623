// The benchmark cases file (`cases.yaml`: a `cases:` list whose items are
// layouts plus `name` and `model`), used by tests, `verify` and the benchmarks.
#pragma once

#include <string>
#include <vector>

#include "model/model.hpp"

namespace proxgen {

struct Case {
  std::string name;
  std::string urdfPath;  // resolved relative to the cases file
  Layout layout;
};

std::vector<Case> loadCases(const std::string& path);

/// The case called `name` of the cases file `path`; an Error naming the file
/// when there is none.
Case loadCase(const std::string& path, const std::string& name);

/// Loads the System of one case.
System loadCaseSystem(const Case& c);

}  // namespace proxgen

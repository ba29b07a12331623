#include "support.hpp"

#include <cstdlib>
#include <filesystem>

namespace proxgen::test {

std::string modelsDir() {
  const std::string dir = PROXGEN_TEST_MODELS_DIR;
  return std::filesystem::exists(std::filesystem::path(dir) / "cases.yaml") ? dir : "";
}

bool underCi() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

std::vector<Case> sharedCases() {
  if (modelsDir().empty()) return {};
  return loadCases(modelsDir() + "/cases.yaml");
}

std::string modelPath(const std::string& file) { return modelsDir() + "/" + file; }

std::string sourceDir() { return PROXGEN_TEST_SOURCE_DIR; }

double relErr(const VecX& a, const VecX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace proxgen::test

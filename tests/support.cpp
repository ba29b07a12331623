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

RandomState randomState(const Model& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  RandomState s{VecX::Zero(m.nq), VecX::Zero(m.nv), VecX::Zero(m.nv)};
  for (int i = 1; i < m.numBodies(); ++i) {
    const Joint& j = m.bodies[i].joint;
    if (j.type == JointType::FreeFlyer) {
      for (int k = 0; k < 3; ++k) s.q[j.idx_q + k] = U(rng);
      Eigen::Vector4d quat(U(rng), U(rng), U(rng), U(rng));
      s.q.segment<4>(j.idx_q + 3) = quat.normalized();
    } else if (j.hasPositionLimits && j.upper > j.lower) {
      std::uniform_real_distribution<double> L(j.lower, j.upper);
      s.q[j.idx_q] = L(rng);
    } else {
      s.q[j.idx_q] = U(rng);
    }
  }
  for (int k = 0; k < m.nv; ++k) {
    s.v[k] = U(rng);
    s.tau[k] = U(rng);
  }
  return s;
}

double relErr(const VecX& a, const VecX& b) {
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace proxgen::test

// What the `eval --compute` tests (test_compute.cpp, test_compute_derivatives.cpp)
// share: the example robots they run on, the names the JSON keys its rows and
// columns by (docs/cli.md), and the exact comparison of a named matrix with
// the library's.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/layout.hpp"
#include "support.hpp"

namespace proxgen::test {

struct Robot {
  std::string urdf, layout;
};

// The examples: a fixed arm with a 6d weld, a floating quadruped on four 3d
// contacts, a floating humanoid with both kinds.
inline std::vector<Robot> exampleRobots() {
  const std::string g = sourceDir() + "/generated/";
  return {{g + "arm/arm.urdf", g + "arm/layout.yaml"},
          {g + "quadruped/quadruped.urdf", g + "quadruped/layout.yaml"},
          {g + "humanoid/humanoid.urdf", g + "humanoid/layout.yaml"}};
}

// "joint" for a one-dof joint, "joint[k]" for slot k of a free flyer (or a
// planar joint).
inline std::vector<std::string> dofNames(const Model& m) {
  std::vector<std::string> out;
  for (int i = 1; i < m.numBodies(); ++i)
    for (int k = 0; k < m.bodies[i].joint.nv; ++k)
      out.push_back(m.bodies[i].joint.nv == 1 ? m.bodies[i].joint.name : m.bodies[i].joint.name + "[" + std::to_string(k) + "]");
  return out;
}

// "constraint[r]" for row r of a constraint.
inline std::vector<std::string> rowNames(const System& sys) {
  std::vector<std::string> out;
  for (const Constraint& c : sys.constraints)
    for (int r = 0; r < c.rows(); ++r) out.push_back(c.name + "[" + std::to_string(r) + "]");
  return out;
}

// A matrix printed as {"rows": [...], "cols": [...], "values": [[...], ...]}
// equals A entry by entry (no tolerance: see the files' headers).
inline void expectMatrix(const nlohmann::json& j, const MatX& A, const std::vector<std::string>& rows,
                         const std::vector<std::string>& cols, const std::string& what) {
  EXPECT_EQ(j.at("rows").get<std::vector<std::string>>(), rows) << what;
  EXPECT_EQ(j.at("cols").get<std::vector<std::string>>(), cols) << what;
  ASSERT_EQ(j.at("values").size(), std::size_t(A.rows())) << what;
  for (Eigen::Index r = 0; r < A.rows(); ++r) {
    ASSERT_EQ(j.at("values")[r].size(), std::size_t(A.cols())) << what;
    for (Eigen::Index c = 0; c < A.cols(); ++c)
      EXPECT_EQ(j.at("values")[r][c].get<double>(), A(r, c)) << what << " (" << r << ", " << c << ")";
  }
}

}  // namespace proxgen::test

// The shape of the derivatives' tangent sweep (emit/pass_inverse_dynamics_derivatives.cpp):
// in the world frame, one block per body forward and one backward, the (dof,
// path dof) pairs in two loops over constant tables, the free flyer's
// translation columns of dtau_dq left out (docs/derivatives.md section 5);
// and the shape of constrained_dynamics_derivatives' dense algebra (section 5 there).
// The values are the harness's business (tests/generated: harness_derivatives.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "emit/generate.hpp"
#include "support.hpp"

namespace proxgen::emit {
namespace {

// The ranges of a `static constexpr int <name>[...] = {lo, hi, ...};` table.
std::vector<std::pair<int, int>> rangeTable(const std::string& source, const std::string& name) {
  const std::regex table("static constexpr int " + name + R"(\[\d+\] = \{([^}]*)\};)");
  std::smatch m;
  if (!std::regex_search(source, m, table)) return {};
  std::vector<int> x;
  const std::string list = m[1].str();
  for (std::size_t at = 0; at < list.size();) {
    std::size_t next = 0;
    x.push_back(std::stoi(list.substr(at), &next));
    at += next;
    while (at < list.size() && (list[at] == ',' || list[at] == ' ')) ++at;
  }
  std::vector<std::pair<int, int>> out;
  for (std::size_t k = 0; k + 1 < x.size(); k += 2) out.push_back({x[k], x[k + 1]});
  return out;
}

TEST(DerivativesCode, TheWorldFrameSweepVisitsEachBodyOnceAndLoopsOverThePairs) {
  // 7 revolute joints in a chain (nv = 7), the source as the passes printed it.
  const std::string source = test::syntheticChainFiles(8, "inverse_dynamics_derivatives").unsharedSource;
  // One block per body and pass: a body-frame sweep prints a block per carried
  // column instead (28 forward blocks for this chain).
  EXPECT_EQ(test::occurrences(source, "// world forward body "), 7);
  EXPECT_EQ(test::occurrences(source, "// world columns body "), 7);
  // No per-body tangent members: with no constraint nothing reads them.
  EXPECT_EQ(source.find("w.dvq_"), std::string::npos);
  // The pairs: rows of dtau_dq and dtau_dv, and the ancestors' rows, in loops.
  EXPECT_EQ(test::occurrences(source, "world_frame_rows<7>("), 2);
  EXPECT_EQ(test::occurrences(source, "world_frame_columns<7>("), 1);
  // In a chain the rows whose path holds dof c are c..6 (c's joint and all below
  // it); dof c's strict subtree is c + 1..6.
  std::vector<std::pair<int, int>> rows, below;
  for (int c = 0; c < 7; ++c) rows.push_back({c, 7});
  EXPECT_EQ(rangeTable(source, "rows_v"), rows);
  EXPECT_EQ(rangeTable(source, "rows_q"), rows);  // the first joint (about x) moves under gravity (along z)
  for (int c = 0; c < 7; ++c) below.push_back({c + 1, 7});
  EXPECT_EQ(rangeTable(source, "below"), below);
}

TEST(DerivativesCode, TheFreeFlyersTranslationsLeaveDtauDqOut) {
  // Moving the whole robot along a straight line changes none of its dynamics
  // (gravity is uniform): u = s x ov_0 = 0 and c = -s x oa_0 = 0 for a linear
  // s, so those columns of dtau_dq are exact zeros and no row reads them; every
  // row of dtau_dv does (the quadruped: q = [base position, quaternion, joints],
  // dq = [linear; angular; joints]).
  const std::string dir = test::sourceDir() + "/generated/quadruped";
  GenerateOptions g;
  g.urdf = dir + "/quadruped.urdf";
  g.layout = dir + "/layout.yaml";
  g.name = "quadruped";
  g.functions = "inverse_dynamics_derivatives";
  const std::string source = generateFiles(g).source;
  // Per column c, the rows [lo, hi) of dtau_dq and dtau_dv it fills.
  const auto q = rangeTable(source, "rows_q"), v = rangeTable(source, "rows_v");
  ASSERT_EQ(q.size(), v.size());
  ASSERT_GT(q.size(), 6u);
  for (std::size_t c = 0; c < q.size(); ++c) {
    EXPECT_LT(v[c].first, v[c].second) << "column " << c << " of dtau_dv is empty";
    if (c < 3)
      EXPECT_EQ(q[c].first, q[c].second) << "dtau_dq fills translation column " << c;
    else
      EXPECT_EQ(q[c], v[c]) << c;
  }
}

// 11 revolute joints in a chain (nv = 11: two blocks of P), a 3d point on the
// tip (nc = 3): constrained_dynamics_derivatives' source.
std::string tipContactChain() {
  return test::syntheticChainFiles(12, "constrained_dynamics_derivatives", "- {name: tip, link: l11, type: 3d}").source;
}

// constrained_dynamics_derivatives through the tau block: W = M^-1 J^T meets
// one nc x nv block (P = M^-1 - W Lt, by blocks of 8 rows up to their last
// column, the rest mirrored), and each input's two outputs come from one pair
// of products over rows of nv + nc with its sparse tangents on the left. The
// literal form multiplied W by each input's block (three full nv x nv products).
TEST(DerivativesCode, TheConstrainedAlgebraGoesThroughTheTauBlock) {
  const std::string source = tipContactChain();
  // W's products: the two blocks of P's rows, each up to its last column.
  EXPECT_EQ(test::occurrences(source, "dense_product_add<"), 2);
  EXPECT_EQ(test::occurrences(source, "dense_product_add<8, 3, 8, 14, 14>(w.cdd_MinvJt, w.cdd_LtS"), 1);
  EXPECT_EQ(test::occurrences(source, "dense_product_add<3, 3, 11, 14, 14>(w.cdd_MinvJt + 24, w.cdd_LtS"), 1);
  // Rows 0..7's columns 8..10 from rows 8..10.
  EXPECT_EQ(test::occurrences(source, "w.cdd_PLt[i * 14 + 8 + j] = w.cdd_PLt[j * 14 + 112 + i];"), 1);
  // Per input q, v: -dtau_dx^T [P | Lt^T] + R2_x^T [Lt | -S_K], rows of 14.
  EXPECT_EQ(test::occurrences(source, "sparse_transposed_product<11, 11, 14>("), 2);
  EXPECT_EQ(test::occurrences(source, "sparse_transposed_product_add<11, 3, 14, 22>("), 2);
}

// S_K, the K proximal steps on the multipliers' tangents as one operator: from
// (G + I/mu)^-1 (proximal_inverse, once) and K - 1 symmetric steps
// (proximal_power), where the K steps from the identity were K forward and back
// substitutions (proximal_step) whose rows each waited on the one before.
TEST(DerivativesCode, TheKStepsOperatorIsFormedFromTheInverse) {
  const std::string source = tipContactChain();
  EXPECT_EQ(test::occurrences(source, "proximal_step"), 0);
  EXPECT_EQ(test::occurrences(source, "proximal_inverse<3>(w.cdd_Lf, w.cdd_X, w.cdd_T, w.cdd_A);"), 1);
  EXPECT_EQ(test::occurrences(source, "for (int k = 0; k < 9; ++k) w.cdd_S[k] = first * w.cdd_A[k];"), 1);
  EXPECT_EQ(test::occurrences(source, "  for (int k = 1; k < s.iterations; ++k) {\n"
                                      "    proximal_power<3>(w.cdd_A, inv_mu, w.cdd_T, w.cdd_S);\n"
                                      "  }"),
            1);
}

// The part functions of a pass (name prefix `part`), their bodies joined.
std::string partBodies(const std::string& source, const std::string& part) {
  const std::regex head("PROXGEN_RT_NOINLINE void " + part + R"(\w*\([^)]*\) noexcept \{\n)");
  std::string out;
  for (auto it = std::sregex_iterator(source.begin(), source.end(), head); it != std::sregex_iterator(); ++it) {
    const std::size_t from = std::size_t(it->position(0) + it->length(0));
    out += source.substr(from, source.find("\n}\n", from) - from) + "\n";
  }
  return out;
}

// constrained_dynamics_derivatives' M^-1 comes after prox_pv of the same q,
// whose elimination left U and D^-1 in the members M^-1's passes read: its
// backward pass (mass_matrix_inverse_factored's) divides by nothing and writes
// neither D^-1 nor an articulated inertia, where mass_matrix_inverse's own
// forms both, body by body (a division per joint whose D = S^T IA S depends on
// q: l1 .. l9; the last two links' D are constants in this chain, and fold).
TEST(DerivativesCode, ItsMassMatrixInverseReadsTheEliminationsFactors) {
  const std::string source =
      test::syntheticChainFiles(12, "constrained_dynamics_derivatives", "- {name: tip, link: l11, type: 3d}").unsharedSource;
  EXPECT_EQ(test::occurrences(source, "  mass_matrix_inverse_factored(q, w, w.cdd_Minv);\n"), 1);
  const std::string own = partBodies(source, "minv_backward_"), factored = partBodies(source, "minvf_backward_");
  ASSERT_FALSE(own.empty());
  ASSERT_FALSE(factored.empty());
  EXPECT_EQ(test::occurrences(own, " = 1.0 / "), 9);
  EXPECT_GT(test::occurrences(own, "w.IA_"), 0);
  EXPECT_EQ(test::occurrences(factored, " / "), 0);
  EXPECT_EQ(std::regex_search(factored, std::regex(R"(w\.(Dinv|IA|U)_\w+(\[\d+\])? = )")), false);
  // What it reads instead: the elimination's D^-1 of every joint that has one.
  for (int l = 1; l <= 9; ++l)
    EXPECT_GT(test::occurrences(factored, "w.Dinv_l" + std::to_string(l)), 0) << "l" << l;
  // The forward pass is the same for both (it reads only members either backward
  // pass writes): printed once, called by both.
  EXPECT_EQ(test::occurrences(source, "minvf_forward"), 0);
  EXPECT_EQ(test::occurrences(source, "  mass_matrix_inverse_forward(w, Minv);\n"), 2);
  EXPECT_FALSE(partBodies(source, "minv_forward_").empty());
}

// The constraint rows come from the sweep's world-frame vectors of each path
// dof (s, u, c, w in the per-dof arrays) and the body's world placement,
// turned into the constraint frame once per row: no per-body motion tangents
// in body coordinates (dvq_, dvv_, daq_, dav_) are formed for them. The tip's
// path is all 11 joints: the first hangs from the world (its q-tangents are
// exact zeros, a column of its own), the second's u keeps some of the first
// joint's folded zeros (a column of its own), the other nine share one loop.
TEST(DerivativesCode, TheConstraintRowsReadTheSweepsWorldFrameVectors) {
  const std::string source = tipContactChain();
  for (const char* tangent : {"w.dvq_", "w.dvv_", "w.daq_", "w.dav_"})
    EXPECT_EQ(source.find(tangent), std::string::npos) << tangent;
  const std::string rows = partBodies(source, "cdd_rows_");
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(test::occurrences(rows, "PROXGEN_RT_NO_UNROLL for (int j = 0; j < 9; ++j) {"), 1);
  EXPECT_EQ(test::occurrences(rows, "// constraint 'tip' rows, columns 2 to 10"), 1);
  for (const char* array : {"w.oS[", "w.oU[", "w.oC[", "w.oW[", "w.cdd_frame_tip["})
    EXPECT_GT(test::occurrences(rows, array), 0) << array;
  // Column 0 (the rooted joint): J and R2_v only, R2_q's entries fold to zero.
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(test::occurrences(rows, "w.cdd_J[" + std::to_string(11 * r) + "] = "), 1) << r;
    EXPECT_EQ(test::occurrences(rows, "w.cdd_R2[" + std::to_string(22 * r) + "] = "), 0) << r;
    EXPECT_EQ(test::occurrences(rows, "w.cdd_R2[" + std::to_string(22 * r + 11) + "] = "), 1) << r;
  }
}

}  // namespace
}  // namespace proxgen::emit

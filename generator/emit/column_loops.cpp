// Column loops: a run of adjacent columns that go through the same arithmetic
// with the same coefficients, emitted as one loop over j instead of a copy of
// the code per column. Used by the tangent sweep of inverse_dynamics_derivatives
// and the forward pass of mass_matrix_inverse (docs/derivatives.md, "Column
// loops"; docs/dynamics.md).
#include <fmt/format.h>

#include "emit/passes.hpp"

namespace proxgen::emit {

namespace {
// Runs shorter than this stay unrolled: a loop of one column is only overhead.
constexpr int kLoopColumns = 2;
}  // namespace

std::vector<std::pair<int, int>> columnRuns(const std::vector<int>& ks, const std::function<bool(int, int)>& joins) {
  std::vector<std::pair<int, int>> runs;
  for (std::size_t n = 0; n < ks.size();) {
    const int k0 = ks[n];
    std::size_t len = 1;
    while (n + len < ks.size() && ks[n + len] == k0 + int(len) && joins(ks[n + len], k0)) ++len;
    if (int(len) < kLoopColumns) len = 1;
    runs.push_back({k0, int(len)});
    n += len;
  }
  return runs;
}

void openColumns(Emit& e, const std::string& ident, int k0, int len, const std::string& label) {
  e.fn.boundary(fmt::format("{}_c{}", ident, k0));
  if (len > 1)
    e.cb().open(fmt::format("for (int j = 0; j < {}; ++j) {{", len),
                {fmt::format("{} columns {} to {}", label, k0, k0 + len - 1)});
  else
    e.cb().open("{", {fmt::format("{} column {}", label, k0)});
}

}  // namespace proxgen::emit

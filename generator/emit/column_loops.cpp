// Column loops: a run of adjacent columns that go through the same arithmetic
// with the same coefficients, emitted as one loop over j instead of a copy of
// the code per column. Used by the forward pass of mass_matrix_inverse
// (docs/dynamics.md; the body-frame tangent sweep of the derivatives used them
// before the world-frame one replaced it: docs/derivatives.md, "Column loops").
#include <fmt/format.h>

#include <cmath>
#include <regex>

#include "emit/passes.hpp"

namespace proxgen::emit {

std::string columnLoopHead(int len) {
  // Kept a loop by the compiler too (runtime.hpp, PROXGEN_RT_NO_UNROLL); the
  // operation count reads the trip count after the pragma (CodeBuilder::open).
  return fmt::format("PROXGEN_RT_NO_UNROLL for (int j = 0; j < {}; ++j) {{", len);
}

std::vector<std::pair<int, int>> columnRuns(const std::vector<int>& ks, const std::function<bool(int, int)>& joins) {
  std::vector<std::pair<int, int>> runs;
  for (std::size_t n = 0; n < ks.size();) {
    const int k0 = ks[n];
    std::size_t len = 1;
    while (n + len < ks.size() && ks[n + len] == k0 + int(len) && joins(ks[n + len], k0)) ++len;
    if (int(len) < kShortestColumnLoop) len = 1;
    runs.push_back({k0, int(len)});
    n += len;
  }
  return runs;
}

void openColumns(Emit& e, const std::string& ident, int k0, int len, const std::string& label) {
  e.fn.boundary(fmt::format("{}_c{}", ident, k0));
  if (len > 1)
    e.cb().open(columnLoopHead(len), {fmt::format("{} columns {} to {}", label, k0, k0 + len - 1)});
  else
    e.cb().open("{", {fmt::format("{} column {}", label, k0)});
}

namespace {

// A column's input entry, for the shape test: a constant or +-(a member slot)
// whose index advances by one per column (FA_p[r][j], minv[idx(s, j)]).
struct Slot {
  Expr value;          // a constant (prefix empty), or the sign of the member
  std::string prefix;  // "w.FA_x[2]" of "w.FA_x[2][17]", "w.minv" of "w.minv[40]"
  int index = -1;
  bool opaque = false;  // anything else: its column stays unrolled
};

Slot slotOf(const CodeBuilder& cb, const Expr& x) {
  Slot s;
  if (x.isConstant()) {
    s.value = x;
    return s;
  }
  static const std::regex member(R"(^(-?)(w\.\w+(?:\[\d+\])?)\[(\d+)\]$)");
  const std::string text = cb.describe(x);
  std::smatch m;
  if (!x.isScaledAtom() || std::abs(x.terms()[0].coeff) != 1.0 || !std::regex_match(text, m, member)) {
    s.opaque = true;
    return s;
  }
  s.value = Expr(m[1].str().empty() ? 1.0 : -1.0);
  s.prefix = m[2].str();
  s.index = std::stoi(m[3].str());
  return s;
}

std::vector<Slot> slotsOf(const CodeBuilder& cb, const std::vector<Expr>& xs) {
  std::vector<Slot> out;
  for (const Expr& x : xs) out.push_back(slotOf(cb, x));
  return out;
}

// Entry a of column k joins entry b of column k0 in one loop.
bool joins(const Slot& a, int k, const Slot& b, int k0) {
  if (a.opaque || b.opaque || a.prefix != b.prefix || a.value.constant() != b.value.constant()) return false;
  return a.prefix.empty() || a.index - b.index == k - k0;
}

// The loop's reading of slot `first` (column k0's): "prefix[idx + j]".
Expr loopRead(CodeBuilder& cb, const Slot& first) {
  if (first.prefix.empty()) return first.value;
  const std::string text = first.index == 0 ? fmt::format("{}[j]", first.prefix)
                                            : fmt::format("{}[{} + j]", first.prefix, first.index);
  return first.value.constant() * cb.member(text);
}

}  // namespace

// Columns k and k0 have entries of one shape (inputs(k): a column's entries).
bool oneShape(const CodeBuilder& cb, const std::function<std::vector<Expr>(int)>& inputs, int k, int k0) {
  const std::vector<Slot> a = slotsOf(cb, inputs(k)), b = slotsOf(cb, inputs(k0));
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!joins(a[r], k, b[r], k0)) return false;
  return true;
}

// The loop's reading of a column's entries: column k0's, indexed [idx + j].
std::vector<Expr> loopReads(CodeBuilder& cb, const std::vector<Expr>& first) {
  std::vector<Expr> out;
  for (const Slot& s : slotsOf(cb, first)) out.push_back(loopRead(cb, s));
  return out;
}

std::vector<Expr> entries(const V6& x) { return {x.begin(), x.end()}; }
V6 toV6(const std::vector<Expr>& x, std::size_t from) {
  V6 v;
  for (std::size_t r = 0; r < 6; ++r) v[r] = x[from + r];
  return v;
}

}  // namespace proxgen::emit

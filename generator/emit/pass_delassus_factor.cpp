// The Delassus pass of proxPV: G + I/mu = L L^T from the rows the elimination
// carried up the support (G(t, u) = sum of KSD_i KS_i over the bodies whose
// subtree holds both rows), and the solves with that factor. With a floating
// base, G = A + Z^T Z: L factors A (zeros between limbs fold away) and the
// rank-6 part goes through Woodbury. Where the rows of two or more limbs meet
// through a few joints only (a branch: two hands below a torso), the blocks
// between them stay in low rank, never formed (LowRank). The generic counterpart:
// algorithms/prox_pv.cpp (Eigen's LLT of the assembled G).
#include <fmt/format.h>

#include <functional>
#include <regex>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

// The rank of the free flyer's share of G, Z^T Z (Z: 6 x nc).
constexpr int kWoodburyRank = 6;

// Per tree row t: the support bodies whose subtree holds it (ascending) and its column there.
std::vector<std::vector<std::pair<int, int>>> rowsAt(const Plan& plan) {
  std::vector<std::vector<std::pair<int, int>>> at(std::size_t(plan.nc));
  for (int i : plan.support) {
    const BodyPlan& b = plan.bodies[std::size_t(i)];
    for (int j = 0; j < b.m(); ++j) at[std::size_t(b.rowStart + j)].push_back({i, j});
  }
  return at;
}

struct Assembly {
  const Plan& plan;
  const ProxRows& rows;
  std::vector<std::vector<std::pair<int, int>>> at;
};

// G(t, u)'s terms as (row t's factor, row u's factor), rows in tree order,
// bodies ascending (Z_i . Z_i at a free flyer or planar joint, but at the
// free flyer `split` whose share goes through Woodbury).
using Terms = std::vector<std::pair<Expr, Expr>>;
Terms delassusTerms(const Assembly& a, int t, int u, int split) {
  Terms g;
  for (const auto& [i, jt] : a.at[std::size_t(t)]) {
    const BodyPlan& b = a.plan.bodies[std::size_t(i)];
    if (u < b.rowStart || u >= b.rowStart + b.m()) continue;
    const int ju = u - b.rowStart;
    const ProxRows::Body& r = a.rows.b[std::size_t(i)];
    if (const int n = int(pickedComponents(b.jointClass).size()); n > 0) {
      if (i == split) continue;
      for (int d = 0; d < n; ++d) g.push_back({r.Z[std::size_t(jt)][std::size_t(d)], r.Z[std::size_t(ju)][std::size_t(d)]});
    } else {
      g.push_back({r.KSD[std::size_t(jt)], r.KS[std::size_t(ju)][0]});
    }
  }
  return g;
}

Expr sumOf(CodeBuilder& cb, const Terms& terms) {
  Expr x;
  for (const auto& [p, q] : terms) x += cb.mul(p, q);
  return x;
}

Expr delassus(CodeBuilder& cb, const Assembly& a, int t, int u, int split) { return sumOf(cb, delassusTerms(a, t, u, split)); }

// The free-flyer body when it carries constraint rows (floating base) and the
// Woodbury split G = B + Z^T Z suits them, else -1: then G + I/mu is factored
// whole, Z^T Z included, as the generic proxPv does.
// The split needs A = B + I/mu well conditioned: woodbury's
// L^-T (I - W S^-1 W^T) L^-1 subtracts two terms of size mu where A has an
// eigenvalue of 1/mu, and multiplies the round-off by mu |G| there (a lone
// welded hull's proxPV qdd was 1.5e-9 off the generic at mu = 1e4, 1.5e-14
// with the whole factor; tests/generated/single_body/). B has such an
// eigenvalue, structurally, wherever rows outnumber the one-dof bodies that
// see them: B sums one rank-one KS^T D^-1 KS per support body below the free
// flyer, and a row is seen by the bodies on its constraint's path up to the
// free flyer (none for a constraint on the free flyer itself). So, for each
// support body j below it: j's subtree rows at most the support bodies of
// that subtree plus j's ancestors below the free flyer; j's own rows at most
// j and those ancestors.
// Nor does the split pay with six rows or fewer: its capacitance S = I + W^T W
// is 6 x 6 whatever nc is, so with nc <= 6 the split factors a matrix as large
// as the whole one and adds W = L^-1 Z^T, W^T W and, per solve, W^T z and W x
// (solo_f3x2, 6 rows: 0.91 of proxPV's time with the whole factor; with 12
// rows the whole factor is 1.08-1.28: docs/emitter.md, "Woodbury from seven rows").
int freeFlyerWithRows(const Plan& plan) {
  auto bp = [&](int i) -> const BodyPlan& { return plan.bodies[std::size_t(i)]; };
  if (plan.nc <= kWoodburyRank) return -1;
  for (int i : plan.support) {
    const BodyPlan& ff = bp(i);
    if (ff.jointClass != JointClass::FreeFlyer || ff.m() == 0) continue;
    if (!ff.constraints.empty()) return -1;
    std::vector<int> inSubtree(plan.bodies.size(), 0), above(plan.bodies.size(), 0);
    for (auto it = plan.support.rbegin(); it != plan.support.rend(); ++it) {
      inSubtree[std::size_t(*it)] += 1;
      if (bp(*it).parent > 0) inSubtree[std::size_t(bp(*it).parent)] += inSubtree[std::size_t(*it)];
    }
    for (int j : plan.support) {  // ascending: parents first
      if (j == i) continue;
      const int p = bp(j).parent;
      above[std::size_t(j)] = p == i ? 0 : above[std::size_t(p)] + 1;
      int own = 0;
      for (int k : bp(j).constraints) own += plan.constraints[std::size_t(k)].rows;
      if (bp(j).m() > inSubtree[std::size_t(j)] + above[std::size_t(j)] || own > 1 + above[std::size_t(j)]) return -1;
    }
    return i;
  }
  return -1;
}

// The schedule (docs/algorithms.md §4.4): an entry coupling two constraints
// times both their activity factors, so an inactive constraint's rows meet the
// others' through exact zeros only. Its own diagonal block stays as it is:
// with zero coupling and a zero right-hand side (F y, lambda0 0) its rows of
// the factor's solves are exact zeros whatever the block holds, and the other
// rows never read it; so the limbs of one contact each pay nothing here.
// A loop over the rows t reads row t's factor from `rowActive` (active_rows[t]).
bool sameConstraint(const Plan& plan, int t, int u) {
  return rowConstraint(plan, plan.rootRows[std::size_t(t)]) == rowConstraint(plan, plan.rootRows[std::size_t(u)]);
}

Expr scheduled(Emit& e, int t, int u, const Expr& g, const Expr* rowActive = nullptr) {
  const std::vector<int>& tree = e.plan.rootRows;
  const int kt = rowConstraint(e.plan, tree[std::size_t(t)]), ku = rowConstraint(e.plan, tree[std::size_t(u)]);
  if (g.isZero() || kt == ku) return g;
  // One statement each, in this order: the order of C++ arguments' evaluation
  // is the compiler's, and these calls create the expressions whose order the
  // printed text follows (generation must not depend on the compiler).
  const Expr at = rowActive ? *rowActive : activeFactor(e, kt);
  const Expr au = activeFactor(e, ku);
  const Expr both = e.cb().mul(at, au);
  const Expr flat = e.cb().flat(g);
  return e.cb().mul(both, flat);
}

// A branch of the rows: a support body with no rows of its own whose
// children hold two or more blocks of rows, and whose path up to the split (or
// the world) is one-dof bodies that see no other rows. Two rows of different
// blocks then meet only at that path: G(t, u) = sum_p KS_p[t] Dinv_p KS_p[u],
// a block of rank r = |path| (the Atlas's two Shadow hands: 15 rows each, r = 3
// torso joints), and rows outside the branch meet its rows only at the split.
struct Branch {
  int at = 0;
  std::vector<int> blocks;  // first row (tree order) of each child's block, then the end
  std::vector<int> path;    // `at` and its ancestors below the split
  int rank() const { return int(path.size()); }
  int count() const { return int(blocks.size()) - 1; }
  int size(int l) const { return blocks[std::size_t(l + 1)] - blocks[std::size_t(l)]; }
  int rows() const { return blocks.back() - blocks.front(); }
};

// Multiply-adds of what the two schemes do differently, for a factor
// followed by `solves` triangular solves (Woodbury's six and two per proximal
// step). Dense: every cross-block entry of G assembled (r each) and of L
// summed over the earlier columns; a block's own entries summed over the
// earlier blocks' columns; each solve touches every cross-block entry of L.
// Low rank: Y_l = L_ll^-1 g_l (r columns), g M_l, the r x r updates, g P_l
// and its r terms per own entry; each solve r per row and block (docs/emitter.md,
// "Low-rank blocks of the Delassus factor").
long denseCost(const Branch& b, int solves) {
  const long r = b.rank();
  long c = 0, prefix = 0;
  for (int l = 0; l < b.count(); ++l) {
    const long n = b.size(l), rest = b.blocks.back() - b.blocks[std::size_t(l + 1)];
    c += rest * (n * (r + prefix) + n * (n - 1) / 2) + n * (n + 1) / 2 * prefix + solves * n * rest;
    prefix += n;
  }
  return c;
}

long lowRankCost(const Branch& b, int solves) {
  const long r = b.rank();
  long c = 0;
  for (int l = 0; l < b.count(); ++l) {
    const long n = b.size(l), rest = b.blocks.back() - b.blocks[std::size_t(l + 1)];
    c += n * r;  // the activity factors
    if (l + 1 < b.count())
      c += n * (n - 1) / 2 * r + rest * r * r + n * r * (r + 1) / 2 + 2 * r * r * r + solves * (n + rest) * r;
    if (l > 0) c += n * r * r + n * (n + 1) / 2 * r;
  }
  return c;
}

// The branches whose low-rank factor costs fewer multiply-adds than the dense one.
std::vector<Branch> lowRankBranches(const Plan& plan, int split) {
  const int solves = 2 * plan.iterations + (split >= 0 ? 6 : 0);
  auto bp = [&](int i) -> const BodyPlan& { return plan.bodies[std::size_t(i)]; };
  std::vector<Branch> out;
  for (int i : plan.support) {
    const BodyPlan& b = bp(i);
    if (i == split || !b.constraints.empty()) continue;
    Branch br;
    br.at = i;
    int next = b.rowStart;
    bool ok = true;
    for (int c : b.children) {
      if (bp(c).m() == 0) continue;
      ok = ok && bp(c).rowStart == next;
      br.blocks.push_back(next);
      next += bp(c).m();
    }
    br.blocks.push_back(next);
    if (!ok || br.count() < 2 || next != b.rowStart + b.m()) continue;
    for (int a = i; a != 0 && a != split; a = bp(a).parent) {
      ok = ok && bp(a).m() == b.m() && pickedComponents(bp(a).jointClass).empty();
      br.path.push_back(a);
    }
    if (ok && lowRankCost(br, solves) < denseCost(br, solves)) out.push_back(br);
  }
  return out;
}

// Where one branch's terms sit in DelassusFactor::lowRank (that vector is
// visited at every part boundary: its expressions move with the factor).
struct LowRankSlots {
  int g = -1;   // g[t][p] = a_t KS_p[t] (activity factor a), rows of the branch
  int y = -1;   // Y[t][p] = (L_ll^-1 g_l)[t][p] for t in block l
  int gm = -1;  // (g M_l)[t][p] for t after block l (current l)
  int gp = -1;  // (g P_l)[t][p] for t in block l (current l)
  int mb = -1, pm = -1;  // M_l and P_l (r x r, current l)
};

class LowRank {
 public:
  LowRank(Emit& e, DelassusFactor& f, const Branch& br, int index) : e_(e), f_(f), br_(br), index_(index) {}

  // Before block l's first column: the terms its columns and the later blocks' read.
  void startBlock(int l) {
    const int r = br_.rank(), n = br_.rows(), s = br_.blocks.front();
    e_.fn.boundary(fmt::format("low_rank_{}", br_.blocks[std::size_t(l)]));
    CodeBuilder& cb = e_.cb();
    cb.open("{", {fmt::format("rows {} to {}, block {} of {}: the blocks meet through {} joints (low rank)", s,
                              br_.blocks.back() - 1, l, br_.count(), r)});
    const ProxRows& rows = *e_.fn.live().rows;
    const Articulated& art = *e_.fn.live().art;
    if (l == 0) {
      s_.g = slots(n * r), s_.y = slots(n * r), s_.gm = slots(br_.count() * n * r), s_.gp = slots(n * r);
      s_.mb = slots(r * r), s_.pm = slots(r * r);
      f_.branches.push_back(DelassusFactor::Branch{br_.blocks, r, s_.y, s_.gm});
      for (int t = s; t < s + n; ++t)
        for (int p = 0; p < r; ++p) {
          const int body = br_.path[std::size_t(p)];
          const Expr on = activeRowFactor(e_, e_.plan.rootRows[std::size_t(t)]);
          const Expr ks = rows.b[std::size_t(body)].KS[std::size_t(t - e_.plan.bodies[std::size_t(body)].rowStart)][0];
          at(s_.g, t - s, p) = e_.put(member("g", n * r, (t - s) * r + p, "activity times KS at the path"), cb.mul(on, ks));
        }
      for (int p = 0; p < r; ++p)
        for (int q = 0; q < r; ++q) {
          at(s_.mb, p, q) = p == q ? art.b[std::size_t(br_.path[std::size_t(p)])].Dinv : Expr();
          at(s_.pm, p, q) = Expr();
        }
    } else {
      // C = Y^T Y over block l - 1, then M_l = M - M C M and P_l = P + M C M.
      std::vector<Expr> C(std::size_t(r * r)), MC(std::size_t(r * r));
      for (int p = 0; p < r; ++p)
        for (int q = p; q < r; ++q) {
          Expr x;
          for (int t = br_.blocks[std::size_t(l - 1)]; t < br_.blocks[std::size_t(l)]; ++t)
            x += cb.mul(at(s_.y, t - s, p), at(s_.y, t - s, q));
          C[std::size_t(p * r + q)] = C[std::size_t(q * r + p)] = cb.flat(x, "C");
        }
      for (int p = 0; p < r; ++p)
        for (int q = 0; q < r; ++q) {
          Expr x;
          for (int k = 0; k < r; ++k) x += cb.mul(at(s_.mb, p, k), C[std::size_t(k * r + q)]);
          MC[std::size_t(p * r + q)] = cb.flat(x, "MC");
        }
      for (int p = 0; p < r; ++p)
        for (int q = p; q < r; ++q) {
          Expr x;
          for (int k = 0; k < r; ++k) x += cb.mul(MC[std::size_t(p * r + k)], at(s_.mb, k, q));
          const Expr mcm = cb.flat(x, "MCM");
          const int pq = (l * r + p) * r + q;
          const Expr pnew = at(s_.pm, p, q) + mcm;
          const Expr mnew = at(s_.mb, p, q) - mcm;
          at(s_.pm, p, q) = at(s_.pm, q, p) = e_.put(member("P", br_.count() * r * r, pq, "low-rank Schur update P_l"), pnew);
          if (!last(l))  // M_l reaches only the later blocks
            at(s_.mb, p, q) = at(s_.mb, q, p) = e_.put(member("M", br_.count() * r * r, pq, "low-rank coupling M_l"), mnew);
        }
      for (int t = br_.blocks[std::size_t(l)]; t < br_.blocks[std::size_t(l + 1)]; ++t)
        for (int p = 0; p < r; ++p)
          at(s_.gp, t - s, p) = e_.put(member("gP", n * r, p * n + t - s, "g P_l, block l (column p, row t)"), times(s_.pm, t - s, p));
    }
    for (int t = br_.blocks[std::size_t(l + 1)]; t < br_.blocks.back(); ++t)
      for (int p = 0; p < r; ++p)
        at(s_.gm, l * n + t - s, p) = e_.put(member("gM", br_.count() * n * r, (l * n + t - s) * r + p, "g M_l, rows after block l"),
                                     times(s_.mb, t - s, p));
    cb.close();
  }

  int blockOf(int t) const {
    for (int l = 0; l < br_.count(); ++l)
      if (t < br_.blocks[std::size_t(l + 1)]) return t >= br_.blocks[std::size_t(l)] ? l : -1;
    return -1;
  }
  int blockStart(int t) const { return br_.blocks[std::size_t(blockOf(t))]; }
  int first() const { return br_.blocks.front(); }
  bool last(int l) const { return l + 1 == br_.count(); }

  // Column j's row of Y: (g[j] - sum over the block's earlier columns L(j, k) Y[k]) / L(j, j).
  void solveRow(int j, const DelassusFactor& f) {
    CodeBuilder& cb = e_.cb();
    const int r = br_.rank(), s = first(), n = br_.rows();
    for (int p = 0; p < r; ++p) {
      Expr x = at(s_.g, j - s, p);
      for (int k = blockStart(j); k < j; ++k) x -= cb.mul(f.L(j, k), at(s_.y, k - s, p));
      const Expr y = cb.mul(cb.flat(x), f.Linv[std::size_t(j)]);
      at(s_.y, j - s, p) = e_.put(member("Y", n * r, (j - s) * r + p, "L_ll^-1 g, block l"), y);
    }
  }
  // The earlier blocks' share of entry (i, j) of one block: (g P_l)[i] . g[j],
  // as (row i's factor, row j's factor).
  Terms updateTerms(int i, int j) {
    Terms x;
    if (blockOf(j) == 0) return x;
    for (int p = 0; p < br_.rank(); ++p) x.push_back({at(s_.gp, i - first(), p), at(s_.g, j - first(), p)});
    return x;
  }
  Expr update(int i, int j) { return sumOf(e_.cb(), updateTerms(i, j)); }

 private:
  int slots(int n) {
    const int at = int(f_.lowRank.size());
    f_.lowRank.resize(f_.lowRank.size() + std::size_t(n));
    return at;
  }
  Expr& at(int base, int t, int p) { return f_.lowRank[std::size_t(base + t * br_.rank() + p)]; }
  Expr times(int mat, int t, int p) {
    Expr x;
    for (int q = 0; q < br_.rank(); ++q) x += e_.cb().mul(at(s_.g, t, q), at(mat, q, p));
    return x;
  }
  std::string member(const std::string& what, int size, int idx, const std::string& comment) {
    return e_.member(fmt::format("lr{}_{}", index_, what), size, idx, comment);
  }

  Emit& e_;
  DelassusFactor& f_;
  const Branch& br_;
  int index_;
  LowRankSlots s_;
};

constexpr const char* kLWhat = "Cholesky factor of G + I/mu (lower, packed)";

// Rows of one column that loop: from four up. Loops of two or three rows (the
// feet's 6-d blocks) made the Atlas f6x2's prox_pv 1.03 slower at the baseline,
// and four left the t3x10's gain as it was (docs/emitter.md, "The Delassus
// columns as loops").
constexpr int kShortestEntryLoop = 4;

// Entry (i, j) of the factor below the diagonal, as its terms:
// L(i, j) = (G(i, j), scheduled, - (g P_l)[i] . g[j] - sum_k L(i, k) L(j, k)) / L(j, j).
struct Entry {
  Terms g, lowRank, chol;  // (row i's factor, row j's factor)
  bool scheduled = false;  // i and j of two constraints: G(i, j) times both activity factors
  bool inBranch = false;   // i and j in one branch's block: its low-rank update
};

// The entry's value: the same operations in the same order wherever it is
// printed, unrolled or in a loop; rowActive: row i's activity factor as a loop reads it.
Expr entryValue(Emit& e, const Entry& en, int i, int j, const Expr& linv, const Expr* rowActive = nullptr) {
  CodeBuilder& cb = e.cb();
  Expr x = en.scheduled ? scheduled(e, i, j, sumOf(cb, en.g), rowActive) : sumOf(cb, en.g);
  if (en.inBranch) x -= sumOf(cb, en.lowRank);
  for (const auto& [p, q] : en.chol) x -= cb.mul(p, q);
  return cb.mul(cb.flat(x), linv);
}

// Row i's factors, the entries a loop over the rows reads at [idx + j].
std::vector<Expr> rowFactors(const Entry& en) {
  std::vector<Expr> out;
  for (const Terms* t : {&en.g, &en.lowRank, &en.chol})
    for (const auto& pq : *t) out.push_back(pq.first);
  return out;
}

// What must be the same in every row of a loop: the flags, and the column's factors.
std::string columnKey(const CodeBuilder& cb, const Entry& en) {
  std::string key = fmt::format("{}{}|", int(en.scheduled), int(en.inBranch));
  for (const Terms* t : {&en.g, &en.lowRank, &en.chol}) {
    for (const auto& pq : *t) key += cb.describe(pq.second) + ";";
    key += "|";
  }
  return key;
}

// Adjacent rows of one column whose entries are one statement over [idx + j]
// (oneShape: each row factor the same constant, or a member slot one further
// per row), as (first row, count); runs shorter than kShortestEntryLoop, and
// runs that read no member, as single rows.
std::vector<std::pair<int, int>> entryRuns(const CodeBuilder& cb, const std::vector<Entry>& entries, const std::vector<int>& rows) {
  const auto factors = [&](int i) { return rowFactors(entries[std::size_t(i)]); };
  std::vector<std::pair<int, int>> runs;
  for (std::size_t n = 0; n < rows.size();) {
    const int i0 = rows[n];
    const std::string key = columnKey(cb, entries[std::size_t(i0)]);
    std::size_t len = 1;
    while (n + len < rows.size() && rows[n + len] == i0 + int(len) &&
           columnKey(cb, entries[std::size_t(rows[n + len])]) == key && oneShape(cb, factors, rows[n + len], i0))
      ++len;
    bool reads = false;
    for (const Expr& x : factors(i0)) reads = reads || !x.isConstant();
    if (int(len) < kShortestEntryLoop || !reads) len = 1;
    runs.push_back({i0, int(len)});
    n += len;
  }
  return runs;
}

// Rows i0 .. i0 + len - 1 of column j as one loop: the compiler's loop
// vectoriser takes two (SSE2) to eight (AVX-512) rows at a time, where the
// unrolled entries were one long scalar expression each.
void loopEntries(Emit& e, const std::vector<Entry>& entries, int i0, int len, int j, DelassusFactor& f, bool& activeRows) {
  const int nc = e.plan.nc;
  const Entry& first = entries[std::size_t(i0)];
  if (first.scheduled && !activeRows) {  // the rows' activity factors, by row, for the loops to read
    for (int t = 0; t < nc; ++t)
      e.cb().store(e.member("active_rows", nc, t, "the activity factor of each row (tree order)"), activeRowFactor(e, e.plan.rootRows[std::size_t(t)]));
    activeRows = true;
  }
  CodeBuilder& cb = e.cb();
  cb.open(columnLoopHead(len), {fmt::format("rows {} to {}", i0, i0 + len - 1)});
  const std::vector<Expr> reads = loopReads(cb, rowFactors(first));
  Entry en = first;
  std::size_t r = 0;
  for (Terms* t : {&en.g, &en.lowRank, &en.chol})
    for (auto& pq : *t) pq.first = reads[r++];
  const Expr act = first.scheduled ? cb.member(e.ws.loopSlot("active_rows", nc, i0, "the activity factor of each row (tree order)")) : Expr();
  e.put(e.ws.loopSlot("L", nc * (nc + 1) / 2, Sym::index(nc, i0, j), kLWhat),
        entryValue(e, en, i0, j, f.Linv[std::size_t(j)], first.scheduled ? &act : nullptr));
  cb.close();
  for (int i = i0; i < i0 + len; ++i) f.L(i, j) = cb.refresh(e.member("L", nc * (nc + 1) / 2, Sym::index(nc, i, j), kLWhat));
}

// G + I/mu = L L^T (or A + I/mu with a floating base), scheduled, one block
// (and part) per column; the blocks of a branch meet through its low-rank terms.
void factorColumns(Emit& e, const Assembly& a, DelassusFactor& f) {
  const int nc = e.plan.nc;
  f.L = Sym(nc);
  f.Linv.assign(std::size_t(nc), Expr());
  const int split = freeFlyerWithRows(e.plan);
  const std::vector<Branch> branches = lowRankBranches(e.plan, split);
  std::vector<LowRank> lr;
  lr.reserve(branches.size());
  for (std::size_t b = 0; b < branches.size(); ++b) lr.emplace_back(e, f, branches[b], int(b));
  bool activeRows = false;  // active_rows stored (loopEntries)
  std::vector<int> branchOf(std::size_t(nc), -1);
  for (std::size_t b = 0; b < branches.size(); ++b)
    for (int t = branches[b].blocks.front(); t < branches[b].blocks.back(); ++t) branchOf[std::size_t(t)] = int(b);
  for (int j = 0; j < nc; ++j) {
    LowRank* lj = branchOf[std::size_t(j)] >= 0 ? &lr[std::size_t(branchOf[std::size_t(j)])] : nullptr;
    const int lb = lj ? lj->blockOf(j) : -1;
    if (lj && j == lj->blockStart(j)) lj->startBlock(lb);
    // Column k of row t is summed over unless both are in one branch, in different blocks (low rank).
    auto summed = [&](int t, int k) { return !lj || branchOf[std::size_t(t)] != branchOf[std::size_t(j)] || k < lj->first() || k >= lj->blockStart(j); };
    e.fn.boundary(fmt::format("column_{}", j));
    CodeBuilder& cb = e.cb();
    cb.open("{", {fmt::format("G + I/mu = L L^T, column {} (Cholesky, unrolled for the fixed row count)", j)});
    Expr d = scheduled(e, j, j, delassus(cb, a, j, j, split));  // before inv_mu: see mulAdd in symbolic.cpp
    d += cb.input("inv_mu");
    if (lj) d -= lj->update(j, j);
    for (int k = 0; k < j; ++k)
      if (summed(j, k)) d -= cb.mul(f.L(j, k), f.L(j, k));
    const Expr r = cb.sqrt(d, "r");
    f.Linv[std::size_t(j)] = e.put(e.member("Linv", nc, j, "1 / diag(L)"), cb.recip(r, "inv"));
    if (lj && !lj->last(lb)) lj->solveRow(j, f);
    std::vector<Entry> entries(static_cast<std::size_t>(nc));
    std::vector<int> below;  // the rows whose entry is formed
    for (int i = j + 1; i < nc; ++i) {
      e.member("L", nc * (nc + 1) / 2, Sym::index(nc, i, j), kLWhat);  // declared in row order
      // between two blocks of a branch: (g M_l)[i] . Y[j], never formed (lowRankForward, lowRankBackward)
      if (lj && branchOf[std::size_t(i)] == branchOf[std::size_t(j)] && lj->blockOf(i) > lb) continue;
      Entry& en = entries[std::size_t(i)];
      en.g = delassusTerms(a, i, j, split);
      en.scheduled = !sameConstraint(e.plan, i, j);
      en.inBranch = lj && branchOf[std::size_t(i)] == branchOf[std::size_t(j)];
      if (en.inBranch) en.lowRank = lj->updateTerms(i, j);
      for (int k = 0; k < j; ++k)
        if (summed(i, k)) en.chol.push_back({f.L(i, k), f.L(j, k)});
      below.push_back(i);
    }
    for (const auto& [i0, len] : entryRuns(cb, entries, below)) {
      if (len == 1) {
        f.L(i0, j) = e.put(e.member("L", nc * (nc + 1) / 2, Sym::index(nc, i0, j), kLWhat),
                           entryValue(e, entries[std::size_t(i0)], i0, j, f.Linv[std::size_t(j)]));
        continue;
      }
      loopEntries(e, entries, i0, len, j, f, activeRows);
    }
    cb.close();
  }
}

// The branch and block of tree row t, or {-1, -1}.
std::pair<int, int> branchBlock(const DelassusFactor& f, int t) {
  for (std::size_t b = 0; b < f.branches.size(); ++b) {
    const std::vector<int>& bl = f.branches[b].blocks;
    if (t < bl.front() || t >= bl.back()) continue;
    for (std::size_t l = 0; l + 1 < bl.size(); ++l)
      if (t < bl[l + 1]) return {int(b), int(l)};
  }
  return {-1, -1};
}

// L(i, k) is an entry of L unless i and k are in different blocks of one branch.
bool inL(const DelassusFactor& f, int i, int k) {
  const auto bi = branchBlock(f, i), bk = branchBlock(f, k);
  return bi.first < 0 || bi.first != bk.first || bi.second == bk.second;
}

// Row i of L y = b before its division by L(i, i): x - sum_k L(i, k) y_k - the
// low-rank terms (g M_l)[i] . w_l of its branch's solved blocks. yOf(k): the
// solved row k; wOf(branch, l * rank + p): w_l[p]. Shared by lowRankForward and
// Woodbury's rows, which read y and w from registers and from W's loops.
Expr forwardRow(CodeBuilder& cb, const DelassusFactor& f, int i, Expr x, const std::function<Expr(int)>& yOf,
                const std::function<Expr(int, int)>& wOf) {
  // The low-rank terms first, then L's in the order of k: each term comes after
  // those known before it (w_l before the rows of block l + 1; y[i - 1] last), so
  // the sum runs while the previous rows are solved, and each row adds one
  // product and one subtraction to the chain of the solve, not its whole sum.
  const auto [bi, l] = branchBlock(f, i);
  if (bi >= 0) {
    const DelassusFactor::Branch& br = f.branches[std::size_t(bi)];
    const int r = br.rank, s = br.blocks.front(), m = br.blocks.back() - s;
    for (int k = 0; k < l; ++k)
      for (int p = 0; p < r; ++p)
        x -= cb.mul(f.lowRank[std::size_t(br.gm + ((k * m + i - s) * r + p))], wOf(bi, k * r + p));
  }
  for (int k = 0; k < i; ++k)
    if (inL(f, i, k) && !f.L(i, k).isZero()) x -= cb.mul(f.L(i, k), yOf(k));
  return x;
}

// L y = b with L's cross-block parts in low rank: once block l is solved,
// w_l = Y_l^T y_l (r values), and a later row i subtracts (g M_l)[i] . w_l.
std::vector<Expr> lowRankForward(CodeBuilder& cb, const DelassusFactor& f, const std::vector<Expr>& b) {
  if (f.branches.empty()) return forwardSolve(cb, f.L, f.Linv, b);
  const int n = f.L.size();
  std::vector<Expr> y(static_cast<std::size_t>(n));
  std::vector<std::vector<Expr>> w(f.branches.size());  // per branch: w_l[p], l * rank + p
  for (int i = 0; i < n; ++i) {
    const Expr x = forwardRow(
        cb, f, i, b[std::size_t(i)], [&](int k) { return y[std::size_t(k)]; },
        [&](int bi, int lp) { return w[std::size_t(bi)][std::size_t(lp)]; });
    const auto [bi, l] = branchBlock(f, i);
    y[std::size_t(i)] = cb.flat(cb.mul(cb.flat(x), f.Linv[std::size_t(i)]), "y");
    if (bi >= 0) {
      const DelassusFactor::Branch& br = f.branches[std::size_t(bi)];
      const int r = br.rank, s = br.blocks.front();
      if (i + 1 == br.blocks[std::size_t(l + 1)] && l + 2 < int(br.blocks.size()))  // block l solved, not the last
        for (int p = 0; p < r; ++p) {
          Expr x;
          for (int t = br.blocks[std::size_t(l)]; t <= i; ++t)
            x += cb.mul(f.lowRank[std::size_t(br.y + (t - s) * r + p)], y[std::size_t(t)]);
          w[std::size_t(bi)].push_back(cb.flat(x, "w"));
        }
    }
  }
  return y;
}

// L^T x = y: before block l's rows (from the bottom), v_l = sum over the later
// blocks' rows t of (g M_l)[t] x[t], and a row j of block l subtracts Y[j] . v_l.
std::vector<Expr> lowRankBackward(CodeBuilder& cb, const DelassusFactor& f, const std::vector<Expr>& y) {
  if (f.branches.empty()) return backwardSolve(cb, f.L, f.Linv, y);
  const int n = f.L.size();
  std::vector<Expr> x(static_cast<std::size_t>(n));
  std::vector<Expr> v;  // v_l of the current block
  for (int i = n - 1; i >= 0; --i) {
    const auto [bi, l] = branchBlock(f, i);
    const DelassusFactor::Branch* br = bi >= 0 ? &f.branches[std::size_t(bi)] : nullptr;
    if (br && i + 1 == br->blocks[std::size_t(l + 1)]) {  // the block's last row: v_l from the rows after it
      const int r = br->rank, s = br->blocks.front(), m = br->blocks.back() - s;
      v.assign(std::size_t(r), Expr());
      for (int p = 0; p < r; ++p) {
        Expr z;  // the rows in the order they were solved (from the bottom)
        for (int t = br->blocks.back() - 1; t >= br->blocks[std::size_t(l + 1)]; --t)
          z += cb.mul(f.lowRank[std::size_t(br->gm + ((l * m + t - s) * r + p))], x[std::size_t(t)]);
        v[std::size_t(p)] = cb.flat(z, "v");
      }
    }
    // As forwardRow: the terms known first come first (v_l, then the rows
    // from the bottom), x[i + 1], the row just solved, last.
    Expr z = y[std::size_t(i)];
    if (br && l + 2 < int(br->blocks.size()))
      for (int p = 0; p < br->rank; ++p)
        z -= cb.mul(f.lowRank[std::size_t(br->y + (i - br->blocks.front()) * br->rank + p)], v[std::size_t(p)]);
    for (int k = n - 1; k > i; --k)
      if (inL(f, k, i)) z -= cb.mul(f.L(k, i), x[std::size_t(k)]);
    x[std::size_t(i)] = cb.flat(cb.mul(cb.flat(z), f.Linv[std::size_t(i)]), "x");
  }
  return x;
}

// Z's entry (row j, column d) as a loop over d reads it, "w.Z_<body>[j][<col>]";
// empty unless all six of the row are the members w.Z_<body>[d][<col>] (none folded).
std::string zLoopRead(const CodeBuilder& cb, const ProxRows::Body& r, int j) {
  static const std::regex slot(R"(^(w\.\w+)\[(\d+)\]\[(\d+)\]$)");
  std::string prefix, col;
  for (int d = 0; d < 6; ++d) {
    const Expr& x = r.Z[std::size_t(j)][std::size_t(d)];
    std::smatch m;
    const std::string text = cb.describe(x);
    if (x.isConstant() || !std::regex_match(text, m, slot) || std::stoi(m[2].str()) != d) return {};
    if (d == 0) prefix = m[1].str(), col = m[3].str();
    if (m[1].str() != prefix || m[3].str() != col) return {};
  }
  return fmt::format("{}[j][{}]", prefix, col);
}

// (A + Z^T Z)^-1 = L^-T (I - W S^-1 W^T) L^-1 with W = L^-1 Z^T, S = I + W^T W
// (Woodbury): six forward solves and a 6 x 6 factor instead of a dense one.
// The six columns go through the same arithmetic on the same factor, so each
// row of W and each row of S is one loop over the columns (woodburyRows): a
// loop of a few iterations over contiguous W[t][0..5] that the compiler's loop
// vectoriser takes two, four or eight at a time, where the columns unrolled
// one after the other were scalar code (the Atlas t3x10: 45 KB for W and 25 KB
// for S; docs/emitter.md, "Woodbury's rows as loops").
//
// So: W = L^-1 Z^T row by row, each row one loop over the six columns j (the
// same statements as lowRankForward's, on W[k][j] in place of y[k]), then S =
// I + W^T W a row per loop, and its factor.
void woodburyRows(Emit& e, const ProxRows& rows, int ff, DelassusFactor& f) {
  const int nc = e.plan.nc;
  const BodyPlan& b = e.bp(ff);
  const ProxRows::Body& r = rows.b[std::size_t(ff)];
  f.W.assign(std::size_t(nc), zero6());
  e.fn.boundary("W");
  // Row t of Z as the loops read it: its members, or (an entry folded: a zero
  // of KA at the top of L^-1 KA) its six values copied to Wz[t] first.
  std::vector<std::string> reads(static_cast<std::size_t>(nc));
  for (int j = 0; j < b.m(); ++j) {
    const int t = b.rowStart + j;
    reads[std::size_t(t)] = zLoopRead(e.cb(), r, j);
    if (!reads[std::size_t(t)].empty()) continue;
    e.cb().open("{", {fmt::format("row {} of Z, some entries folded: staged for the loops", t)});
    for (int d = 0; d < 6; ++d)
      e.cb().store(e.ws.member("Wz", nc, 6, t, d, "Z^T rows with folded entries"), r.Z[std::size_t(j)][std::size_t(d)]);
    e.cb().close();
    reads[std::size_t(t)] = e.ws.loopSlot("Wz", nc, 6, t, 0, "Z^T rows with folded entries");
  }
  const std::string what = "L^-1 Z^T";
  // Row t of W as a loop reads it: its constant (the same in every column) or w.W[t][j].
  std::vector<Expr> fixed(static_cast<std::size_t>(nc));
  std::vector<char> stored(static_cast<std::size_t>(nc), 0);
  const auto rowAt = [&](CodeBuilder& cb, int t, int c0 = 0) {  // column c0 + j
    return stored[std::size_t(t)] ? cb.member(e.ws.loopSlot("W", nc, 6, t, c0, what)) : fixed[std::size_t(t)];
  };
  // Per branch, w_l[p] = Y_l^T y_l of its solved blocks (member Wlr<b>[l * rank + p][j]).
  const auto wlrSlot = [&](std::size_t bi, int lp) {
    const DelassusFactor::Branch& br = f.branches[bi];
    const int n = (int(br.blocks.size()) - 2) * br.rank;
    return e.ws.loopSlot(fmt::format("Wlr{}", bi), n, 6, lp, 0, "Y_l^T (L^-1 Z^T)_l, the rows of block l");
  };
  for (int i = 0; i < nc; ++i) {
    CodeBuilder& cb = e.cb();
    cb.open(columnLoopHead(6), {fmt::format("W = L^-1 Z^T, row {}, columns 0 to 5", i)});
    Expr x;
    if (!reads[std::size_t(i)].empty()) {  // Z F: an inactive row's column of Z is 0, so is its row of W
      // Two statements: the printed order of the factors follows the order their atoms are made,
      // which must not be the compiler's order of evaluating a call's arguments.
      const Expr on = activeRowFactor(e, e.plan.rootRows[std::size_t(i)]);
      const Expr z = cb.member(reads[std::size_t(i)]);
      x = cb.mul(on, z);
    }
    x = forwardRow(
        cb, f, i, x, [&](int k) { return rowAt(cb, k); },
        [&](int bi, int lp) { return cb.member(wlrSlot(std::size_t(bi), lp)); });
    const auto [bi, l] = branchBlock(f, i);
    const Expr y = e.put(e.ws.loopSlot("W", nc, 6, i, 0, what), cb.mul(cb.flat(x), f.Linv[std::size_t(i)]));
    stored[std::size_t(i)] = !y.isConstant();
    if (!stored[std::size_t(i)]) fixed[std::size_t(i)] = y;
    cb.close();
    if (bi < 0) continue;
    const DelassusFactor::Branch& br = f.branches[std::size_t(bi)];
    if (i + 1 != br.blocks[std::size_t(l + 1)] || l + 2 >= int(br.blocks.size())) continue;
    const int rk = br.rank, s0 = br.blocks.front();
    for (int p = 0; p < rk; ++p) {  // block l solved, not the last: its w_l
      CodeBuilder& lb = e.cb();
      lb.open(columnLoopHead(6), {fmt::format("W's low-rank terms, branch {}, block {}, column {} of Y", bi, l, p)});
      Expr z;
      for (int t = br.blocks[std::size_t(l)]; t <= i; ++t)
        z += lb.mul(f.lowRank[std::size_t(br.y + (t - s0) * rk + p)], rowAt(lb, t));
      e.put(wlrSlot(std::size_t(bi), l * rk + p), z);
      lb.close();
    }
  }
  // After the loops each column's entries are in W: read them by their own names.
  CodeBuilder& cb = e.cb();
  for (int t = 0; t < nc; ++t)
    for (int d = 0; d < 6; ++d)
      f.W[std::size_t(t)][std::size_t(d)] =
          stored[std::size_t(t)] ? cb.refresh(e.ws.member("W", nc, 6, t, d, what)) : fixed[std::size_t(t)];
  e.fn.boundary("LS");
  Sym S(6);
  const std::string sWhat = "W^T W (row a, column j)";
  for (int a = 0; a < 6; ++a) {  // the upper triangle: row a, columns a to 5
    CodeBuilder& lb = e.cb();
    lb.open(columnLoopHead(6 - a), {fmt::format("W^T W, row {}, columns {} to 5", a, a)});
    Expr x;
    for (int t = 0; t < nc; ++t) x += lb.mul(f.W[std::size_t(t)][std::size_t(a)], rowAt(lb, t, a));
    const Expr sa = e.put(e.ws.loopSlot("WtW", 6, 6, a, a, sWhat), x);
    lb.close();
    for (int c = a; c < 6; ++c)
      S(a, c) = (a == c ? Expr(1.0) : Expr()) + (sa.isConstant() ? sa : e.cb().refresh(e.ws.member("WtW", 6, 6, a, c, sWhat)));
  }
  e.cb().open("{", {"S = I + W^T W = LS LS^T"});
  const Cholesky ch = cholesky(
      e, S, Expr(), [&](int rr, int c) { return e.member("LS", 21, Sym::index(6, rr, c), "factor of I + W^T W (lower, packed)"); },
      [&](int rr) { return e.member("LSinv", 6, rr, "1 / diag(LS)"); });
  f.LS = ch.L;
  f.LSinv = ch.inv;
  e.cb().close();
}

}  // namespace

DelassusFactor factorDelassus(Emit& e, const ProxRows& rows) {
  DelassusFactor f;
  const InScope<DelassusFactor> scope(e.fn.live().del, &f);
  const Assembly a{e.plan, rows, rowsAt(e.plan)};
  factorColumns(e, a, f);
  if (const int ff = freeFlyerWithRows(e.plan); ff >= 0) woodburyRows(e, rows, ff, f);
  return f;
}

std::vector<Expr> solveDelassus(Emit& e, const DelassusFactor& f, const std::vector<Expr>& rhs) {
  CodeBuilder& cb = e.cb();
  std::vector<Expr> z = lowRankForward(cb, f, rhs);
  if (!f.W.empty()) {
    std::vector<Expr> v(6);
    for (int d = 0; d < 6; ++d)
      for (std::size_t t = 0; t < z.size(); ++t) v[std::size_t(d)] += cb.mul(f.W[t][std::size_t(d)], z[t]);
    const std::vector<Expr> x = choleskySolve(cb, f.LS, f.LSinv, v);
    for (std::size_t t = 0; t < z.size(); ++t) {  // x[0] last: the backward solve's last
      for (int d = 5; d >= 0; --d) z[t] -= cb.mul(f.W[t][std::size_t(d)], x[std::size_t(d)]);
      z[t] = cb.flat(z[t], "z");
    }
  }
  return lowRankBackward(cb, f, z);
}

}  // namespace proxgen::emit

// The Delassus pass of proxPV: G + I/mu = L L^T from the rows the elimination
// carried up the support (G(t, u) = sum of KSD_i KS_i over the bodies whose
// subtree holds both rows), and the solves with that factor. With a floating
// base, G = A + Z^T Z: L factors A (zeros between limbs fold away) and the
// rank-6 part goes through Woodbury. The generic counterpart:
// algorithms/prox_pv.cpp (Eigen's LLT of the assembled G).
#include <fmt/format.h>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

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

// G(t, u), rows in tree order (Z_i . Z_i at a free flyer or planar joint, but
// at the free flyer `split` whose share goes through Woodbury).
Expr delassus(CodeBuilder& cb, const Assembly& a, int t, int u, int split) {
  Expr g;
  for (const auto& [i, jt] : a.at[std::size_t(t)]) {
    const BodyPlan& b = a.plan.bodies[std::size_t(i)];
    if (u < b.rowStart || u >= b.rowStart + b.m()) continue;
    const int ju = u - b.rowStart;
    const ProxRows::Body& r = a.rows.b[std::size_t(i)];
    if (const int n = int(pickedComponents(b.jointClass).size()); n > 0) {
      if (i == split) continue;
      for (int d = 0; d < n; ++d) g += cb.mul(r.Z[std::size_t(jt)][std::size_t(d)], r.Z[std::size_t(ju)][std::size_t(d)]);
    } else {
      g += cb.mul(r.KSD[std::size_t(jt)], r.KS[std::size_t(ju)][0]);
    }
  }
  return g;
}

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
int freeFlyerWithRows(const Plan& plan) {
  auto bp = [&](int i) -> const BodyPlan& { return plan.bodies[std::size_t(i)]; };
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
Expr scheduled(Emit& e, int t, int u, const Expr& g) {
  const std::vector<int>& tree = e.plan.rootRows;
  const int kt = rowConstraint(e.plan, tree[std::size_t(t)]), ku = rowConstraint(e.plan, tree[std::size_t(u)]);
  if (g.isZero() || kt == ku) return g;
  // One statement each, in this order: the order of C++ arguments' evaluation
  // is the compiler's, and these calls create the expressions whose order the
  // printed text follows (generation must not depend on the compiler).
  const Expr at = activeFactor(e, kt);
  const Expr au = activeFactor(e, ku);
  const Expr both = e.cb().mul(at, au);
  const Expr flat = e.cb().flat(g);
  return e.cb().mul(both, flat);
}

// G + I/mu = L L^T (or A + I/mu with a floating base), scheduled, one block (and part) per column.
void factorColumns(Emit& e, const Assembly& a, DelassusFactor& f) {
  const int nc = e.plan.nc;
  f.L = Sym(nc);
  f.Linv.assign(std::size_t(nc), Expr());
  const int split = freeFlyerWithRows(e.plan);
  for (int j = 0; j < nc; ++j) {
    e.fn.boundary(fmt::format("column_{}", j));
    CodeBuilder& cb = e.cb();
    cb.open("{", {fmt::format("G + I/mu = L L^T, column {} (Cholesky, unrolled for the fixed row count)", j)});
    Expr d = scheduled(e, j, j, delassus(cb, a, j, j, split));  // before inv_mu: see mulAdd in symbolic.cpp
    d += cb.input("inv_mu");
    for (int k = 0; k < j; ++k) d -= cb.mul(f.L(j, k), f.L(j, k));
    const Expr r = cb.sqrt(d, "r");
    f.Linv[std::size_t(j)] = e.put(e.member("Linv", nc, j, "1 / diag(L)"), cb.recip(r, "inv"));
    for (int i = j + 1; i < nc; ++i) {
      Expr x = scheduled(e, i, j, delassus(cb, a, i, j, split));
      for (int k = 0; k < j; ++k) x -= cb.mul(f.L(i, k), f.L(j, k));
      f.L(i, j) = e.put(e.member("L", nc * (nc + 1) / 2, Sym::index(nc, i, j), "Cholesky factor of G + I/mu (lower, packed)"),
                        cb.mul(cb.flat(x), f.Linv[std::size_t(j)]));
    }
    cb.close();
  }
}

// (A + Z^T Z)^-1 = L^-T (I - W S^-1 W^T) L^-1 with W = L^-1 Z^T, S = I + W^T W
// (Woodbury): six forward solves and a 6 x 6 factor instead of a dense one.
void woodbury(Emit& e, const ProxRows& rows, int ff, DelassusFactor& f) {
  const int nc = e.plan.nc;
  const BodyPlan& b = e.bp(ff);
  f.W.assign(std::size_t(nc), zero6());
  for (int d = 0; d < 6; ++d) {
    e.fn.boundary(fmt::format("W_{}", d));
    e.cb().open("{", {fmt::format("W = L^-1 Z^T, column {}", d)});
    std::vector<Expr> z(static_cast<std::size_t>(nc));
    for (int j = 0; j < b.m(); ++j)  // Z F: an inactive row's column of Z is 0, so is its row of W
      z[std::size_t(b.rowStart + j)] = e.cb().mul(activeRowFactor(e, e.plan.rootRows[std::size_t(b.rowStart + j)]),
                                                  rows.b[std::size_t(ff)].Z[std::size_t(j)][std::size_t(d)]);
    const std::vector<Expr> w = forwardSolve(e.cb(), f.L, f.Linv, z);
    for (int t = 0; t < nc; ++t)
      f.W[std::size_t(t)][std::size_t(d)] = e.put(e.ws.member("W", nc, 6, t, d, "L^-1 Z^T"), w[std::size_t(t)]);
    e.cb().close();
  }
  e.fn.boundary("LS");
  CodeBuilder& cb = e.cb();
  cb.open("{", {"S = I + W^T W = LS LS^T"});
  Sym S(6);
  for (int a = 0; a < 6; ++a)
    for (int c = a; c < 6; ++c) {
      Expr x = a == c ? Expr(1.0) : Expr();
      for (int t = 0; t < nc; ++t) x += cb.mul(f.W[std::size_t(t)][std::size_t(a)], f.W[std::size_t(t)][std::size_t(c)]);
      S(a, c) = x;
    }
  const Cholesky ch = cholesky(
      e, S, Expr(), [&](int r, int c) { return e.member("LS", 21, Sym::index(6, r, c), "factor of I + W^T W (lower, packed)"); },
      [&](int r) { return e.member("LSinv", 6, r, "1 / diag(LS)"); });
  f.LS = ch.L;
  f.LSinv = ch.inv;
  cb.close();
}

}  // namespace

DelassusFactor factorDelassus(Emit& e, const ProxRows& rows) {
  DelassusFactor f;
  const InScope<DelassusFactor> scope(e.fn.live().del, &f);
  const Assembly a{e.plan, rows, rowsAt(e.plan)};
  factorColumns(e, a, f);
  if (const int ff = freeFlyerWithRows(e.plan); ff >= 0) woodbury(e, rows, ff, f);
  return f;
}

std::vector<Expr> solveDelassus(Emit& e, const DelassusFactor& f, const std::vector<Expr>& rhs) {
  CodeBuilder& cb = e.cb();
  std::vector<Expr> z = forwardSolve(cb, f.L, f.Linv, rhs);
  if (!f.W.empty()) {
    std::vector<Expr> v(6);
    for (int d = 0; d < 6; ++d)
      for (std::size_t t = 0; t < z.size(); ++t) v[std::size_t(d)] += cb.mul(f.W[t][std::size_t(d)], z[t]);
    const std::vector<Expr> x = backwardSolve(cb, f.LS, f.LSinv, forwardSolve(cb, f.LS, f.LSinv, v));
    for (std::size_t t = 0; t < z.size(); ++t) {
      for (int d = 0; d < 6; ++d) z[t] -= cb.mul(f.W[t][std::size_t(d)], x[std::size_t(d)]);
      z[t] = cb.flat(z[t], "z");
    }
  }
  return backwardSolve(cb, f.L, f.Linv, z);
}

}  // namespace proxgen::emit

// proxPV (docs/algorithms.md §4.2): one elimination sweep carrying the
// constraint rows up the support (KA, KS = S^T KA, D^-1 KS), the free row
// accelerations y_free, the Delassus matrix G + I/mu factored once
// (pass_delassus_factor.cpp), K proximal solves, one forward sweep with the
// multipliers. The generic counterpart: algorithms/prox_pv.cpp.
#include <fmt/format.h>

#include <functional>
#include <stdexcept>

#include "emit/passes.hpp"

namespace proxgen::emit {
void initOwnRows(Emit& e, int i, ProxRows& rows) {
  ProxRows::Body& b = rows.b[std::size_t(i)];
  b.KA.assign(std::size_t(e.bp(i).m()), zero6());
  int col = 0;
  for (int k : e.bp(i).constraints) {
    const Constraint& c = e.sys.constraints[std::size_t(k)];
    const Mat6 X = c.placement.motionMatrixInv();
    for (int j = 0; j < c.rows(); ++j, ++col) b.KA[std::size_t(col)] = constant(Vec6(X.row(j).transpose()));
  }
}

namespace {

/// Slots per row of the row-major KA and Z: m columns and one unused slot.
int rowStride(int m) { return m + 1; }

// How many columns from c0 on hold exactly the members KA_i[r][c]
// (each entry stored, none folded): a loop over them reads the same slots.
int loopableColumns(Emit& e, const ProxRows::Body& b, int i, int c0) {
  const int m = e.bp(i).m(), stride = rowStride(m);
  int c = c0;
  for (; c < m; ++c) {
    bool canonical = true;
    for (int r = 0; r < 6 && canonical; ++r) {
      const Expr& x = b.KA[std::size_t(c)][std::size_t(r)];
      canonical = x.isScaledAtom() && x.terms()[0].coeff == 1.0 &&
                  x.terms()[0].atom == e.cb().member(e.member(kKA, i, 6, stride, r, c)).terms()[0].atom;
    }
    if (!canonical) break;
  }
  return c - c0;
}

// Body i's carried columns in order: each run of stored columns long enough
// for a loop (loopableColumns) to `run(c0, len)`, every other column to `one(c)`.
void forEachColumnRun(Emit& e, const ProxRows::Body& b, int i, const std::function<void(int, int)>& run,
                      const std::function<void(int)>& one) {
  const int m = e.bp(i).m();
  for (int c0 = 0; c0 < m;) {
    if (const int len = loopableColumns(e, b, i, c0); len >= kShortestColumnLoop) {
      run(c0, len);
      c0 += len;
    } else {
      one(c0++);
    }
  }
}

// KS = S^T KA ; KA_p[cols] = X^T (KA - U D^-1 KS). The LA recursion
// (LA_p[block] = LA + KS^T D^-1 KS) sums up the tree to the Delassus matrix
// G = sum over the support of KS^T D^-1 KS at each body's rows: the Delassus
// pass assembles it from KS and KSD = D^-1 KS. The lA recursion gives the
// rows' free accelerations y_free = K a_free - k: freeRowAccelerations takes
// them from a forward pass with lambda = 0 instead (fewer products for many rows).
// KA is stored row-major: each column goes through the same arithmetic with
// the same coefficients, so with a row's columns adjacent in memory the
// compiler packs 2 or 4 columns into one vector instruction (SLP). A row of m
// columns takes m + 1 slots (rowStride): the unused slot keeps the stores of
// two rows, which differ in their arithmetic, out of one store group.
void rowsOneDof(Emit& e, const Kinematics& kin, const Articulated& art, int i, ProxRows& rows) {
  CodeBuilder& cb = e.cb();
  ProxRows::Body& b = rows.b[std::size_t(i)];
  const Articulated::Body& ab = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const int m = p.m(), off = p.offsetInParent;
  const V6& S = kb.S[0];
  const int along = axisComponent(p);
  const bool passes = p.parent != 0;  // KA_0 only met the root acceleration, in y_free
  V6 UD;
  if (passes)
    for (int r = 0; r < 6; ++r) UD[std::size_t(r)] = cb.flat(cb.mul(ab.U[0][std::size_t(r)], ab.Dinv), "UD");
  b.KS.assign(std::size_t(m), std::vector<Expr>(1));
  b.KSD.resize(std::size_t(m));
  auto plain = [&](const Expr& x) { return x.isConstant() || cb.isAlias(x); };  // nothing to store
  // One column: KS, KSD, and (below the root) its column of the parent's KA.
  // `ka` reads the column, `at` names the column's slot of this body's KS or
  // KSD ("[c0 + j]" in a loop over j, "[c]" unrolled).
  auto column = [&](const V6& ka, const std::function<std::string(const Quantity&)>& at) {
    struct Out {
      Expr ks, ksd;
      V6 f;
      bool ksdStored = false;
    } out;
    const Expr ks = dot(cb, S, ka);
    out.ks = plain(ks) ? ks : cb.store(at(kKS), ks);
    const Expr ksd = cb.mul(ab.Dinv, out.ks);
    out.ksdStored = !plain(ksd);
    out.ksd = out.ksdStored ? cb.store(at(kKSD), ksd) : ksd;
    if (!passes) return out;
    // U (D^-1 KS) when D^-1 KS is stored: one product per entry, where
    // (U D^-1) KS costs two for an entry of U that is a constant.
    V6 col;
    for (int r = 0; r < 6; ++r)
      col[std::size_t(r)] = ka[std::size_t(r)] - (out.ksdStored ? cb.mul(ab.U[0][std::size_t(r)], out.ksd)
                                                                : cb.mul(UD[std::size_t(r)], out.ks));
    if (along >= 0) col[std::size_t(along)] = Expr();  // S^T (KA - U D^-1 KS) = 0
    out.f = e.forceToParent(kb, col);
    return out;
  };
  const int stride = rowStride(m), mp = passes ? e.bp(p.parent).m() : 0, pstride = rowStride(mp);
  ProxRows::Body& par = rows.b[std::size_t(p.parent)];
  // A run of columns c0 .. c0 + len - 1 goes through identical arithmetic: one
  // loop (vectorised by the compiler) instead of len copies of the code.
  const auto run = [&](int c0, int len) {
    cb.open(columnLoopHead(len), {fmt::format("columns {} to {}", c0, c0 + len - 1)});
    V6 ka;
    for (int r = 0; r < 6; ++r) ka[std::size_t(r)] = cb.member(e.loopSlot(kKA, i, 6, stride, r, c0));
    const auto out = column(ka, [&](const Quantity& qy) { return e.loopSlot(qy, i, m, c0); });
    if (passes)
      for (int r = 0; r < 6; ++r)
        cb.store(e.loopSlot(kKA, p.parent, 6, pstride, r, off + c0), out.f[std::size_t(r)]);
    if (!out.ksdStored) throw std::logic_error("emitter: a looped column's D^-1 KS is not stored");
    cb.close();
    for (int c = c0; c < c0 + len; ++c) {
      const auto cu = std::size_t(c);
      const Expr ks = dot(cb, S, b.KA[cu]);  // the loop's KS for column c: a pick of KA prints nothing
      b.KS[cu][0] = plain(ks) ? ks : cb.member(e.member(kKS, i, m, c));
      b.KSD[cu] = cb.member(e.member(kKSD, i, m, c));
      if (passes)
        for (int r = 0; r < 6; ++r)
          par.KA[std::size_t(off + c)][std::size_t(r)] = cb.member(e.member(kKA, p.parent, 6, pstride, r, off + c));
    }
  };
  const auto one = [&](int c0) {
    const auto out = column(b.KA[std::size_t(c0)], [&](const Quantity& qy) { return e.member(qy, i, m, c0); });
    b.KS[std::size_t(c0)][0] = out.ks;
    b.KSD[std::size_t(c0)] = out.ksd;
    if (passes)
      for (int r = 0; r < 6; ++r)
        par.KA[std::size_t(off + c0)][std::size_t(r)] =
            e.put(e.member(kKA, p.parent, 6, pstride, r, off + c0), out.f[std::size_t(r)]);
  };
  forEachColumnRun(e, b, i, run, one);
}

// At the free flyer (S = I, D = IA = L L^T, parent the world, KA_0 = 0):
// its share of G is Z^T Z with Z = L^-1 KA.
void rowsFreeFlyer(Emit& e, const Articulated& art, int i, ProxRows& rows) {
  ProxRows::Body& b = rows.b[std::size_t(i)];
  const Articulated::Body& ab = art.b[std::size_t(i)];
  const int m = e.bp(i).m();
  b.KS.assign(std::size_t(m), std::vector<Expr>(6));
  for (int j = 0; j < m; ++j)
    for (int d = 0; d < 6; ++d) b.KS[std::size_t(j)][std::size_t(d)] = b.KA[std::size_t(j)][std::size_t(d)];
  b.Z.resize(std::size_t(m));
  CodeBuilder& cb = e.cb();
  const int stride = rowStride(m);
  // A run of columns c0 .. c0 + len - 1 holding stored KA entries: one loop
  // (vectorised by the compiler, two columns per register) instead of len solves.
  const auto run = [&](int c0, int len) {
    cb.open(columnLoopHead(len), {fmt::format("Z = L^-1 KA, columns {} to {}", c0, c0 + len - 1)});
    std::vector<Expr> ka(6);
    for (int r = 0; r < 6; ++r) ka[std::size_t(r)] = cb.member(e.loopSlot(kKA, i, 6, stride, r, c0));
    const std::vector<Expr> z = forwardSolve(cb, ab.L, ab.Linv, ka);
    for (int d = 0; d < 6; ++d) cb.store(e.loopSlot(kZ, i, 6, stride, d, c0), z[std::size_t(d)]);
    cb.close();
    for (int c = c0; c < c0 + len; ++c)
      for (int d = 0; d < 6; ++d) b.Z[std::size_t(c)][std::size_t(d)] = cb.member(e.member(kZ, i, 6, stride, d, c));
  };
  const auto one = [&](int c0) {
    const std::vector<Expr> z =
        forwardSolve(cb, ab.L, ab.Linv, std::vector<Expr>(b.KA[std::size_t(c0)].begin(), b.KA[std::size_t(c0)].end()));
    for (int d = 0; d < 6; ++d)
      b.Z[std::size_t(c0)][std::size_t(d)] = e.keep(e.member(kZ, i, 6, stride, d, c0), z[std::size_t(d)]);
  };
  forEachColumnRun(e, b, i, run, one);
}

// At a planar joint (S picks sel, D = L L^T): KS = KA[sel], its share of G is
// Z^T Z with Z = L^-1 KS, and below a moving parent the parent's KA gets
// X^T (KA - U D^-1 KS), D^-1 KS = L^-T Z (its components sel vanish).
void rowsPicked(Emit& e, const Kinematics& kin, const Articulated& art, int i, ProxRows& rows) {
  CodeBuilder& cb = e.cb();
  ProxRows::Body& b = rows.b[std::size_t(i)];
  const Articulated::Body& ab = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const std::vector<int> sel = pickedComponents(p.jointClass);
  const int n = int(sel.size()), m = p.m(), off = p.offsetInParent;
  const int pstride = p.parent != 0 ? rowStride(e.bp(p.parent).m()) : 0;
  b.KS.assign(std::size_t(m), std::vector<Expr>(std::size_t(n)));
  b.Z.assign(std::size_t(m), zero6());
  for (int j = 0; j < m; ++j) {
    const V6& ka = b.KA[std::size_t(j)];
    for (int d = 0; d < n; ++d) b.KS[std::size_t(j)][std::size_t(d)] = ka[std::size_t(sel[std::size_t(d)])];
    const std::vector<Expr> z = forwardSolve(cb, ab.L, ab.Linv, b.KS[std::size_t(j)]);
    std::vector<Expr> zk(static_cast<std::size_t>(n));
    for (int d = 0; d < n; ++d)
      zk[std::size_t(d)] = b.Z[std::size_t(j)][std::size_t(d)] = e.keep(e.member(kZ, i, n, rowStride(m), d, j), z[std::size_t(d)]);
    if (p.parent == 0) continue;
    const std::vector<Expr> x = backwardSolve(cb, ab.L, ab.Linv, zk);  // D^-1 KS
    V6 col;
    for (int r = 0; r < 6; ++r) {
      col[std::size_t(r)] = ka[std::size_t(r)];
      for (int d = 0; d < n; ++d) col[std::size_t(r)] -= cb.mul(ab.U[std::size_t(d)][std::size_t(r)], x[std::size_t(d)]);
    }
    for (int k : sel) col[std::size_t(k)] = Expr();  // S^T (KA - U D^-1 KS) = 0
    const V6 f = e.forceToParent(kb, col);
    ProxRows::Body& par = rows.b[std::size_t(p.parent)];
    for (int r = 0; r < 6; ++r)
      par.KA[std::size_t(off + j)][std::size_t(r)] = e.put(e.member(kKA, p.parent, 6, pstride, r, off + j), f[std::size_t(r)]);
  }
}

void carryRows(Emit& e, const Kinematics& kin, const Articulated& art, int i, ProxRows& rows) {
  if (e.bp(i).m() == 0) return;
  if (e.bp(i).jointClass == JointClass::FreeFlyer) rowsFreeFlyer(e, art, i, rows);
  else if (e.bp(i).jointClass == JointClass::Planar) rowsPicked(e, kin, art, i, rows);
  else rowsOneDof(e, kin, art, i, rows);
}

// KA of the support bodies (and the world) starts from their own rows: KA = K^T.
void initRows(Emit& e, ProxRows& rows) {
  initOwnRows(e, 0, rows);
  for (int i : e.plan.support) initOwnRows(e, i, rows);
}

// y_free = K a_free - k: the rows' accelerations with lambda = 0, from a
// forward pass over the support (the a_i members are rewritten by the final pass).
void freeRowAccelerations(Emit& e, const Kinematics& kin, const Articulated& art, Motion& motion, ProxRows& rows) {
  for (int i : e.plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "free acceleration (lambda = 0):");
    accelerateBody(e, kin, art, i, art.b[std::size_t(i)].u, false, motion);
    e.cb().close();
  }
  e.fn.boundary("yfree");
  e.cb().open("{", {"free row accelerations y_free = K a - k (tree order)"});
  for (std::size_t k = 0; k < e.sys.constraints.size(); ++k) {
    const Constraint& c = e.sys.constraints[k];
    const std::vector<Expr> Ka = e.constraintRows(int(k), c.body == 0 ? e.rootAcceleration() : motion.a[std::size_t(c.body)]);
    for (int j = 0; j < c.rows(); ++j) {
      const int t = e.plan.rowPosition[std::size_t(c.row + j)];
      // times the activity factor: an inactive row's right-hand side is exactly 0 (docs/algorithms.md §4.4)
      // (one statement per created expression: argument order is the compiler's)
      const Expr on = activeFactor(e, int(k));
      const Expr y = e.cb().flat(Ka[std::size_t(j)] - kin.k[k][std::size_t(j)]);
      rows.yfree[std::size_t(t)] = e.put(e.yMember(t), e.cb().mul(on, y));
    }
  }
  e.cb().close();
}

// The rows' residual K a - k = J qdd + gamma - a* of the final accelerations
// (residual(w) reads it; constrainedABA stores it in its multiplier update).
void storeResidual(Emit& e, const Kinematics& kin, const Motion& motion) {
  e.fn.beginPass("residual", "the rows' residual K a - k of the final accelerations");
  e.fn.boundary("");
  e.cb().open("{", {"residual rows K a - k (layout order)"});
  for (std::size_t k = 0; k < e.sys.constraints.size(); ++k) {
    const Constraint& c = e.sys.constraints[k];
    const std::vector<Expr> Ka = e.constraintRows(int(k), c.body == 0 ? e.rootAcceleration() : motion.a[std::size_t(c.body)]);
    for (int j = 0; j < c.rows(); ++j) {  // 0 for an inactive constraint
      const Expr on = activeFactor(e, int(k));  // before the row: argument order is the compiler's
      const Expr res = e.cb().flat(Ka[std::size_t(j)] - kin.k[k][std::size_t(j)]);
      e.cb().store(residualMember(e, c.row + j), e.cb().mul(on, res));
    }
  }
  e.cb().close();
}

std::string fingerprint(const CodeBuilder& cb, const Multipliers& mult) {
  std::string f;
  for (const Expr& x : mult.lambda) f += cb.describe(x) + ";";
  for (const Expr& x : mult.dlambda) f += cb.describe(x) + ";";
  return f;
}

}  // namespace

std::string emitProxPv(Emit& e, Kinematics kin, Articulated art, const CodeBuilder* from, ProxPvEnd* end) {
  const Plan& plan = e.plan;
  const int nc = plan.nc;
  Motion motion{std::vector<V6>(art.b.size(), zero6()), std::vector<Expr>(std::size_t(plan.nv))};
  Multipliers mult{std::vector<Expr>(std::size_t(nc)), std::vector<Expr>(std::size_t(nc))};
  ProxRows rows;
  rows.b.resize(art.b.size());
  rows.yfree.assign(std::size_t(nc), Expr());
  DelassusFactor del;
  e.fn.live() = Live{&kin, &art, &motion, nullptr, &rows, &mult, nullptr};
  e.fn.beginHost("pv", from);
  storeActiveFactors(e, "s.active");
  e.cb().line("kinematics(q, v, w);", {}, {"q", "v", "w"});
  if (!plan.offSupport.empty()) e.cb().line("eliminate_free_bodies(tau, w);", {}, {"tau", "w"});
  initRows(e, rows);
  e.fn.beginPass("backward", "backward: eliminate the support, carrying the subtree rows KA, KS = S^T KA, D^-1 KS");
  for (auto it = plan.support.rbegin(); it != plan.support.rend(); ++it) {
    e.fn.boundary(*it);
    e.openBody(*it, "eliminate, carrying the subtree rows:");
    eliminateBody(e, kin, *it, nullptr, art);
    carryRows(e, kin, art, *it, rows);
    e.cb().close();
  }
  if (nc > 0) {
    e.fn.beginPass("free", "free accelerations (lambda = 0) and the rows' y_free = K a - k");
    freeRowAccelerations(e, kin, art, motion, rows);
    e.fn.endPart();
    e.fn.setHostInvMu(e.cb().define("inv_mu", e.cb().literal(1.0) + " / s.mu", {}, {"s"}));
    e.fn.beginPass("delassus", "G + I/mu = L L^T, G assembled from the carried rows");
    del = factorDelassus(e, rows);
    e.fn.live().del = &del;
    startMultipliers(e, mult);
    const std::vector<int>& tree = plan.rootRows;
    const std::string before = fingerprint(e.cb(), mult);
    e.cb().open("for (int k = 0; k < s.iterations; ++k) {",
                {"K proximal steps: (G + I/mu) lambda+ = y_free + lambda / mu (rows in tree order, stored in layout order)"},
                {"s"});
    e.fn.beginPass("proximal", "proximal step: (G + I/mu) lambda = y_free + lambda / mu");
    e.fn.boundary("");
    std::vector<Expr> rhs(static_cast<std::size_t>(nc));
    for (int t = 0; t < nc; ++t)
      rhs[std::size_t(t)] = rows.yfree[std::size_t(t)] + e.cb().mul(e.cb().input("inv_mu"), mult.lambda[std::size_t(tree[std::size_t(t)])]);
    const std::vector<Expr> x = solveDelassus(e, del, rhs);
    for (int t = 0; t < nc; ++t)
      mult.lambda[std::size_t(tree[std::size_t(t)])] = e.cb().store(e.lambdaMember(tree[std::size_t(t)]), x[std::size_t(t)]);
    e.fn.endPart();
    if (fingerprint(e.cb(), mult) != before)
      throw std::logic_error("emitter: the proximal loop does not carry its state consistently");
    e.cb().close();
  }
  e.fn.beginPass("forward", "forward: accelerations, with the multipliers of the subtree rows");
  for (int i : plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "accelerate, with the multipliers of the subtree rows:");
    std::vector<Expr> uEff = art.b[std::size_t(i)].u;
    const ProxRows::Body& rb = rows.b[std::size_t(i)];
    for (int j = 0; j < e.bp(i).m(); ++j) {
      const Expr& lam = mult.lambda[std::size_t(e.bp(i).subtreeRows[std::size_t(j)])];
      for (std::size_t d = 0; d < uEff.size(); ++d) uEff[d] -= e.cb().mul(rb.KS[std::size_t(j)][d], lam);
    }
    accelerateBody(e, kin, art, i, uEff, true, motion);
    e.cb().close();
  }
  if (nc > 0) storeResidual(e, kin, motion);
  callAccelerateFree(e, kin, art, motion);
  copyOut(e, motion, mult);
  std::string text = e.fn.endHost({"q", "v", "tau", "s", "w", "qdd", "lambda"});
  e.fn.live() = Live{};
  if (end) *end = ProxPvEnd{kin, art, e.fn.lastHost()};  // kin and art are the host's values now
  return text;
}

}  // namespace proxgen::emit

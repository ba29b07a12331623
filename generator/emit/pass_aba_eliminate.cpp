// The articulated-body elimination (the backward pass of ABA), leaves first:
// per body U = IA S, D^-1 = (S^T U)^-1, u = tau - S^T pA, and its articulated
// inertia and bias seen from the parent. constrainedABA adds the penalty
// mu K^T K at the constrained bodies first (docs/algorithms.md §4.1). The
// generic counterpart: algorithms/aba.cpp.
#include <fmt/format.h>

#include <stdexcept>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

std::string tauIn(int k) { return fmt::format("tau[{}]", k); }

// IA_i += mu_c K^T K ; pA_i -= mu_c K^T k for every constraint c on body i,
// mu_c = mu times c's activity factor (docs/algorithms.md §4.4): an inactive
// constraint adds exact zeros.
void penalty(Emit& e, int i, const std::vector<std::vector<Expr>>& kk, Sym& IA, V6& pA) {
  CodeBuilder& cb = e.cb();
  const Expr muAll = cb.input("mu");
  for (int k : e.bp(i).constraints) {
    const Expr mu = cb.temp(cb.mul(muAll, activeFactor(e, k)), "mu_c");  // one product, not one per use
    const Constraint& c = e.sys.constraints[std::size_t(k)];
    const Mat6 X = c.placement.motionMatrixInv();
    const auto K = X.topRows(c.rows());
    const Mat6 KtK = K.transpose() * K;
    for (int r = 0; r < 6; ++r)
      for (int col = r; col < 6; ++col) IA(r, col) += KtK(r, col) * mu;
    for (int r = 0; r < 6; ++r) {
      Expr Ktk;
      for (int j = 0; j < c.rows(); ++j) Ktk += K(j, r) * kk[std::size_t(k)][std::size_t(j)];
      pA[std::size_t(r)] -= cb.mul(mu, Ktk);
    }
  }
}

// A body's share of its parent: Ia (and, given, the bias pa) moved into the
// parent's frame and added to its IA (and pA); both transforms are printed
// before the sums, as the elimination always printed them.
void passToParent(Emit& e, const Kinematics::Body& kb, int parent, const Sym& Ia, const V6* pa, Articulated& art) {
  const Sym dI = e.inertiaToParent(kb, Ia);
  const V6 dp = pa ? e.forceToParent(kb, *pa) : V6{};
  Articulated::Body& par = art.b[std::size_t(parent)];
  for (int k = 0; k < 21; ++k)
    if (!dI.packed(k).isZero()) par.IA.packed(k) = e.putQ(kIA, parent, 21, k, par.IA.packed(k) + dI.packed(k));
  if (!pa) return;
  for (int k = 0; k < 6; ++k)
    if (!dp[std::size_t(k)].isZero())
      par.pA[std::size_t(k)] = e.putQ(kPA, parent, 6, k, par.pA[std::size_t(k)] + dp[std::size_t(k)]);
}

void eliminateOneDof(Emit& e, const Kinematics& kin, int i, const std::vector<std::vector<Expr>>* kk, Articulated& art,
                     bool bias) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  Sym IA = b.IA;
  V6 pA = b.pA;
  if (kk) penalty(e, i, *kk, IA, pA);
  const V6& S = kb.S[0];
  V6 U;
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < 6; ++k) U[std::size_t(r)] += cb.mul(IA(r, k), S[std::size_t(k)]);
  b.U.assign(1, V6{});
  for (int r = 0; r < 6; ++r) b.U[0][std::size_t(r)] = e.keepQ(kU, i, 6, r, U[std::size_t(r)]);
  const Expr D = cb.flat(dot(cb, S, b.U[0]), "D");
  if (D.isConstant()) {
    // Folded: the division is correctly rounded here as at run time (in the
    // solver's scalar type), so the value is the one the code would compute.
    b.Dinv = e.plan.scalar == ScalarType::Float ? Expr(double(1.0f / float(D.constant()))) : Expr(1.0 / D.constant());
  } else {
    b.Dinv = cb.storeRaw(e.member(kDinv, i, 0, 0), cb.literal(1.0) + " / " + cb.print(D), {D}, Ops::divisions(1));
  }
  if (bias) {
    const Expr tau = cb.input(tauIn(p.idx_v));  // before the products: see mulAdd in symbolic.cpp
    b.u.assign(1, e.putQ(kUu, i, 1, 0, tau - dot(cb, S, pA)));
  }
  if (p.parent == 0) return;
  // Ia = IA - U D^-1 U^T (its row and column along an axis-aligned S vanish:
  // Ia S = 0) ; pa = pA + Ia c + U D^-1 u.
  // Along an axis-aligned S (S = s e_k, s = +-1): U_k = s D, so (U D^-1)_k = s,
  // exactly; nothing is computed for it (its products were IA_kk / IA_kk).
  const int along = axisComponent(p);
  V6 UD;
  for (int r = 0; r < 6; ++r)
    UD[std::size_t(r)] = r == along ? Expr(p.axisSign) : cb.flat(cb.mul(b.U[0][std::size_t(r)], b.Dinv), "UD");
  // U_r D^-1 U_c with the product that is already a temporary: a constant U_r
  // makes (U D^-1)_r = U_r * D^-1 a scaled atom, and U_r * (U D^-1)_c reuses
  // the temporary of column c (one multiplication instead of two).
  auto udu = [&](int r, int col) {
    const Expr& Ur = b.U[0][std::size_t(r)];
    const Expr& Uc = b.U[0][std::size_t(col)];
    if (Ur.isConstant() && !Uc.isConstant()) return cb.mul(Ur, UD[std::size_t(col)]);
    return cb.mul(UD[std::size_t(r)], Uc);
  };
  Sym Ia(6);
  for (int r = 0; r < 6; ++r)
    for (int col = r; col < 6; ++col) Ia(r, col) = IA(r, col) - udu(r, col);
  if (along >= 0)
    for (int k = 0; k < 6; ++k) Ia(along, k) = Expr();
  flatten(cb, Ia, "Ia");
  if (!bias) {  // the articulated inertia only (the Delassus functions)
    passToParent(e, kb, p.parent, Ia, nullptr, art);
    return;
  }
  V6 pa;
  for (int r = 0; r < 6; ++r) {
    if (r == along) {
      // S^T pa = S^T pA + u = tau (Ia S = 0): pa_k = s tau, exactly, where
      // pA_k + s (tau - s pA_k) would cancel in floating point.
      pa[std::size_t(r)] = p.axisSign * cb.input(tauIn(p.idx_v));
      continue;
    }
    Expr x = pA[std::size_t(r)] + cb.mul(UD[std::size_t(r)], b.u[0]);
    for (int k = 0; k < 6; ++k) x += cb.mul(Ia(r, k), kb.c[std::size_t(k)]);
    pa[std::size_t(r)] = x;
  }
  flatten(cb, pa, "pa");
  passToParent(e, kb, p.parent, Ia, &pa, art);
}

// The free flyer: S = I, so U = IA and D = IA, factored once (LL^T); its
// parent is the world, so nothing passes on.
void eliminateFreeFlyer(Emit& e, int i, const std::vector<std::vector<Expr>>* kk, Articulated& art, bool bias) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  if (p.parent != 0) throw std::logic_error("emitter: a free flyer below another body");
  V6 pA = b.pA;
  if (kk) {
    penalty(e, i, *kk, b.IA, pA);
    for (int k = 0; k < 21; ++k) b.IA.packed(k) = e.keepQ(kIA, i, 21, k, b.IA.packed(k));
  }
  const Cholesky ch = cholesky(
      e, b.IA, Expr(), [&](int r, int c) { return e.member(kL, i, 21, Sym::index(6, r, c)); },
      [&](int r) { return e.member(kLinv, i, 6, r); });
  b.L = ch.L;
  b.Linv = ch.inv;
  b.U.assign(6, V6{});
  for (int d = 0; d < 6; ++d)
    for (int r = 0; r < 6; ++r) b.U[std::size_t(d)][std::size_t(r)] = b.IA(r, d);
  if (!bias) return;
  b.u.resize(6);
  for (int d = 0; d < 6; ++d)
    b.u[std::size_t(d)] = e.putQ(kUu, i, 6, d, cb.input(tauIn(p.idx_v + d)) - pA[std::size_t(d)]);
}

}  // namespace

void factorPicked(Emit& e, int i, const Sym& IA, Articulated::Body& b) {
  const std::vector<int> sel = pickedComponents(e.bp(i).jointClass);
  const int n = int(sel.size());
  b.U.assign(std::size_t(n), V6{});
  for (int d = 0; d < n; ++d)
    for (int r = 0; r < 6; ++r)
      b.U[std::size_t(d)][std::size_t(r)] = e.keepQ(kU, i, 6 * n, 6 * d + r, IA(r, sel[std::size_t(d)]));
  Sym D(n);
  for (int a = 0; a < n; ++a)
    for (int c = a; c < n; ++c) D(a, c) = b.U[std::size_t(c)][std::size_t(sel[std::size_t(a)])];
  const Cholesky ch = cholesky(
      e, D, Expr(), [&](int r, int c) { return e.member(kL, i, n * (n + 1) / 2, Sym::index(n, r, c)); },
      [&](int r) { return e.member(kLinv, i, n, r); });
  b.L = ch.L;
  b.Linv = ch.inv;
}

Sym reducedPicked(CodeBuilder& cb, const Sym& IA, const Articulated::Body& b, const std::vector<int>& sel) {
  const int n = int(sel.size());
  // Y = L^-1 U^T (one solve per row of U), so U D^-1 U^T = Y^T Y.
  std::vector<std::vector<Expr>> Y(6);
  for (int r = 0; r < 6; ++r) {
    std::vector<Expr> row(static_cast<std::size_t>(n));
    for (int d = 0; d < n; ++d) row[std::size_t(d)] = b.U[std::size_t(d)][std::size_t(r)];
    Y[std::size_t(r)] = forwardSolve(cb, b.L, b.Linv, row);
  }
  Sym Ia(6);
  for (int r = 0; r < 6; ++r)
    for (int col = r; col < 6; ++col) {
      Expr x = IA(r, col);
      for (int d = 0; d < n; ++d) x -= cb.mul(Y[std::size_t(r)][std::size_t(d)], Y[std::size_t(col)][std::size_t(d)]);
      Ia(r, col) = x;
    }
  for (int k : sel)
    for (int c = 0; c < 6; ++c) Ia(k, c) = Expr();
  flatten(cb, Ia, "Ia");
  return Ia;
}

namespace {

// A planar joint: S picks the components sel (linear x, linear y, angular z),
// so U = IA S is three columns of IA, D = S^T IA S their 3 x 3 block (LL^T)
// and u = tau - pA[sel]. Below a moving parent Ia = IA - U D^-1 U^T (whose
// rows and columns sel vanish: Ia S = 0) and pa = pA + Ia c + U D^-1 u pass on.
void eliminatePicked(Emit& e, const Kinematics& kin, int i, const std::vector<std::vector<Expr>>* kk, Articulated& art,
                     bool bias) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const std::vector<int> sel = pickedComponents(p.jointClass);
  const int n = int(sel.size());
  Sym IA = b.IA;
  V6 pA = b.pA;
  if (kk) penalty(e, i, *kk, IA, pA);
  factorPicked(e, i, IA, b);
  if (bias) {
    b.u.resize(std::size_t(n));
    for (int d = 0; d < n; ++d)
      b.u[std::size_t(d)] =
          e.putQ(kUu, i, n, d, cb.input(tauIn(p.idx_v + d)) - pA[std::size_t(sel[std::size_t(d)])]);
  }
  if (p.parent == 0) return;
  const Sym Ia = reducedPicked(cb, IA, b, sel);
  if (!bias) {  // the articulated inertia only (the Delassus functions)
    passToParent(e, kb, p.parent, Ia, nullptr, art);
    return;
  }
  const std::vector<Expr> Du = choleskySolve(cb, b.L, b.Linv, b.u);  // D^-1 u
  V6 pa;
  for (int r = 0; r < 6; ++r) {
    Expr x = pA[std::size_t(r)];
    for (int d = 0; d < n; ++d) x += cb.mul(b.U[std::size_t(d)][std::size_t(r)], Du[std::size_t(d)]);
    for (int k = 0; k < 6; ++k) x += cb.mul(Ia(r, k), kb.c[std::size_t(k)]);
    pa[std::size_t(r)] = x;
  }
  flatten(cb, pa, "pa");
  passToParent(e, kb, p.parent, Ia, &pa, art);
}

}  // namespace

Articulated startElimination(const Kinematics& kin) {
  Articulated art;
  art.b.resize(kin.b.size());
  for (std::size_t i = 0; i < kin.b.size(); ++i) {
    art.b[i].IA = kin.b[i].IA;
    art.b[i].pA = kin.b[i].pA;
  }
  return art;
}

void eliminateBody(Emit& e, const Kinematics& kin, int i, const std::vector<std::vector<Expr>>* k, Articulated& art,
                   bool bias) {
  if (e.bp(i).jointClass == JointClass::FreeFlyer) eliminateFreeFlyer(e, i, k, art, bias);
  else if (e.bp(i).jointClass == JointClass::Planar) eliminatePicked(e, kin, i, k, art, bias);
  else eliminateOneDof(e, kin, i, k, art, bias);
}

Articulated eliminateFreeBodies(Emit& e, const Kinematics& kin) {
  Articulated art = startElimination(kin);
  const InScope<Articulated> scope(e.fn.live().art, &art);
  for (auto it = e.plan.offSupport.rbegin(); it != e.plan.offSupport.rend(); ++it) {
    e.fn.boundary(*it);
    e.openBody(*it, "eliminate");
    eliminateBody(e, kin, *it, nullptr, art);
    e.cb().close();
  }
  return art;
}

}  // namespace proxgen::emit

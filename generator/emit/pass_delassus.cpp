// The Delassus functions, generated (docs/dynamics.md, "Delassus recursion"):
// delassus G = J M^-1 J^T and delassus_inverse (G + I/mu)^-1, both by the
// recursion of the generic delassusRecursion on J (M + mu J^T J)^-1 J^T
// (mu = 0 for G), without forming M or J and without an m x m factorisation:
//  - the articulated elimination of every body (pass_aba_eliminate.cpp, its
//    inertia only), with the penalty mu K^T K at the constrained bodies for
//    the inverse;
//  - forward over the support, the apparent inverse inertia
//    Phi_i = S D^-1 S^T + P^T (iXp Phi_p iXp^T) P, P = 1 - U D^-1 S^T
//    (at a free flyer, IA^-1 = L^-T L^-1 from its Cholesky factor; at a
//    planar joint S D^-1 S^T and P through its 3 x 3 D's factor);
//  - backward over the support, each row's force direction carried up
//    (B = X^T P per joint; along an unbranched link with more than
//    kMapColumns columns, the 6 x 6 product of the B's instead, so columns
//    move only at the key bodies: constrained or branching), and every entry
//    once, at the body where its two rows meet: KA_a . Phi KA_b.
// delassus_inverse is then mu I - mu^2 J (M + mu J^T J)^-1 J^T (Woodbury).
// Its round-off: the two terms cancel to the answer's size, so its absolute
// error is about eps mu^2 |J M_mu^-1 J^T| ~ eps mu (delassus.hpp's note).
// The generic counterpart: algorithms/delassus.cpp.
#include <fmt/format.h>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

constexpr Quantity kPhi{"Phi", "apparent inverse inertia (upper triangle)"};
constexpr Quantity kKD{"KD", "constraint force directions of the subtree rows (Delassus), 6 x m"};
constexpr Quantity kT{"T", "map of the rows' force directions below (Delassus), 6 x 6"};

// The halves of a 6 x 6 swapped ([linear; angular] <-> [angular; linear]):
// a motion transform is the force transform of the same placement with its
// halves swapped, so congruence (force side) serves the motion side too.
Sym swapHalves(const Sym& A) {
  Sym B(6);
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) B(r, c) = A((r + 3) % 6, (c + 3) % 6);
  return B;
}

XSym inverse(CodeBuilder& cb, const XSym& X) {
  XSym Y;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Y.R[std::size_t(3 * r + c)] = X.R[std::size_t(3 * c + r)];
  const V3 p = rotateT(cb, X.R, X.p);
  for (int k = 0; k < 3; ++k) Y.p[std::size_t(k)] = -p[std::size_t(k)];
  return Y;
}

// iXp Phi iXp^T: Phi from parent to child coordinates (both sides motion), with
// X = XT XJ, so iXp = XJ^-1 XT^-1 (motionToChild's order).
Sym toChild(Emit& e, int i, const Kinematics::Body& b, const Sym& Phi) {
  const XSym XTinv = constant(e.model().bodies[std::size_t(i)].treePlacement.inverse());
  const Sym A = congruence(e.cb(), XTinv, swapHalves(Phi));
  Sym B = congruence(e.cb(), inverse(e.cb(), b.XJ), A);
  flatten(e.cb(), B, "Ph");
  return swapHalves(B);
}

// Phi_i at a planar joint: S D^-1 S^T + P^T Phi' P, P = 1 - UD S^T with UD = U D^-1
// (6 x n): P^T Phi' P = Phi' - S Yd^T - Yd S^T + S (UD^T Yd) S^T, Yd = Phi' UD.
Sym apparentInverseInertiaPicked(Emit& e, const Kinematics& kin, const Articulated& art, const ConstraintOutputs& st,
                                 int i) {
  CodeBuilder& cb = e.cb();
  const BodyPlan& p = e.bp(i);
  const Articulated::Body& ab = art.b[std::size_t(i)];
  const std::vector<int> sel = pickedComponents(p.jointClass);
  const std::size_t n = sel.size();
  std::vector<std::vector<Expr>> Dinv(n);  // column c of D^-1
  for (std::size_t c = 0; c < n; ++c) {
    std::vector<Expr> unit(n);
    unit[c] = Expr(1.0);
    Dinv[c] = choleskySolve(cb, ab.L, ab.Linv, unit);
    for (Expr& x : Dinv[c]) x = cb.flat(x, "Di");
  }
  Sym Phi(6);
  std::vector<Expr> SAS(n * n);  // the n x n block that S ... S^T places at (sel, sel)
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) SAS[a * n + b] = Dinv[b][a];
  if (p.parent != 0) {
    const Sym Pp = toChild(e, i, kin.b[std::size_t(i)], st.Phi[std::size_t(p.parent)]);
    std::vector<V6> UD(n), Yd(n);
    for (std::size_t c = 0; c < n; ++c) {
      V6 u = zero6();
      for (std::size_t d = 0; d < n; ++d) u = add(u, scale(cb, Dinv[c][d], ab.U[d]));
      flatten(cb, u, "UD");
      UD[c] = u;
      Yd[c] = mul(cb, Pp, u);
      flatten(cb, Yd[c], "yd");
    }
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < n; ++b) SAS[a * n + b] += cb.flat(dot(cb, UD[a], Yd[b]), "alpha");
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) {
        Expr x = Pp(r, c);
        for (std::size_t a = 0; a < n; ++a) {
          if (sel[a] == r) x -= Yd[a][std::size_t(c)];
          if (sel[a] == c) x -= Yd[a][std::size_t(r)];
        }
        Phi(r, c) = x;
      }
  }
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
      if (sel[a] <= sel[b]) Phi(sel[a], sel[b]) += SAS[a * n + b];
  return Phi;
}

Sym apparentInverseInertia(Emit& e, const Kinematics& kin, const Articulated& art, const ConstraintOutputs& st, int i) {
  CodeBuilder& cb = e.cb();
  const BodyPlan& p = e.bp(i);
  const Articulated::Body& ab = art.b[std::size_t(i)];
  if (p.jointClass == JointClass::Planar) return apparentInverseInertiaPicked(e, kin, art, st, i);
  Sym Phi(6);
  if (p.jointClass == JointClass::FreeFlyer) {
    // IA^-1 = N^T N, N = L^-1 (column c: L^-1 e_c).
    std::vector<std::vector<Expr>> N;
    for (int c = 0; c < 6; ++c) {
      std::vector<Expr> unit(6);
      unit[std::size_t(c)] = 1.0;
      N.push_back(forwardSolve(cb, ab.L, ab.Linv, unit));
    }
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) {
        Expr x;
        for (int k = 0; k < 6; ++k) x += cb.mul(N[std::size_t(r)][std::size_t(k)], N[std::size_t(c)][std::size_t(k)]);
        Phi(r, c) = x;
      }
    return Phi;
  }
  const V6& S = kin.b[std::size_t(i)].S[0];
  if (p.parent != 0) {
    // P^T Phi' P = Phi' - S yd^T - yd S^T + alpha S S^T, yd = Phi' U D^-1, alpha = D^-1 U^T yd.
    const Sym Pp = toChild(e, i, kin.b[std::size_t(i)], st.Phi[std::size_t(p.parent)]);
    V6 UD;
    for (int r = 0; r < 6; ++r) UD[std::size_t(r)] = cb.flat(cb.mul(ab.U[0][std::size_t(r)], ab.Dinv), "UD");
    V6 yd = mul(cb, Pp, UD);
    flatten(cb, yd, "yd");
    const Expr alpha = cb.flat(dot(cb, UD, yd), "alpha");
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) {
        const double srsc = (S[std::size_t(r)].constant() * S[std::size_t(c)].constant());
        Phi(r, c) = Pp(r, c) - S[std::size_t(r)].constant() * yd[std::size_t(c)] -
                    S[std::size_t(c)].constant() * yd[std::size_t(r)] + srsc * alpha;
      }
  }
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c)
      Phi(r, c) += (S[std::size_t(r)].constant() * S[std::size_t(c)].constant()) * ab.Dinv;
  return Phi;
}

// Above this many columns, an unbranched link of the support without rows of
// its own accumulates the 6 x 6 map B (its child's B times the child's map,
// six column moves) instead of moving every column (docs/dynamics.md): what
// keeps the columns' moves to the key bodies, O(n + m^2) as the generic
// recursion (its Data::Tkey).
constexpr int kMapColumns = 6;

// B x = X^T (x - U D^-1 S^T x): a force on child `ch` carried to its parent.
V6 throughJoint(Emit& e, const Kinematics& kin, const Articulated& art, int ch, const V6& x) {
  CodeBuilder& cb = e.cb();
  const Articulated::Body& ab = art.b[std::size_t(ch)];
  const Kinematics::Body& kb = kin.b[std::size_t(ch)];
  if (e.bp(ch).jointClass == JointClass::Planar) {  // x - U D^-1 S^T x, its components sel exactly 0
    const std::vector<int> sel = pickedComponents(e.bp(ch).jointClass);
    std::vector<Expr> rhs;  // S^T x
    for (int k : sel) rhs.push_back(x[std::size_t(k)]);
    const std::vector<Expr> y = choleskySolve(cb, ab.L, ab.Linv, rhs);  // D^-1 S^T x
    V6 f = x;
    for (std::size_t d = 0; d < sel.size(); ++d) f = sub(f, scale(cb, y[d], ab.U[d]));
    for (int k : sel) f[std::size_t(k)] = Expr();
    return e.forceToParent(kb, f);
  }
  const Expr ks = cb.flat(dot(cb, kb.S[0], x), "ks");
  V6 f;
  for (int r = 0; r < 6; ++r) f[std::size_t(r)] = x[std::size_t(r)] - cb.mul(cb.mul(ab.U[0][std::size_t(r)], ab.Dinv), ks);
  // S^T f = 0: along an axis-aligned S the component is exactly 0.
  if (const int along = axisComponent(e.bp(ch)); along >= 0) f[std::size_t(along)] = Expr();
  return e.forceToParent(kb, f);
}

// T x for a row-major 6 x 6 map T (empty: the identity).
V6 apply(CodeBuilder& cb, const std::vector<Expr>& T, const V6& x) {
  if (T.empty()) return x;
  V6 y;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) y[std::size_t(r)] += cb.mul(T[std::size_t(6 * r + c)], x[std::size_t(c)]);
  return y;
}

// Body i of the backward sweep: the columns of its support children moved in
// (or, on an unbranched link with many columns, only their map extended), then
// the entries of the pairs of rows that meet here (own rows with every row,
// rows of two different children), once each.
void rowsAt(Emit& e, const Kinematics& kin, const Articulated& art, ConstraintOutputs& st, ProxRows& rows,
            std::vector<int>& keyBelow, int i, bool inverse) {
  CodeBuilder& cb = e.cb();
  const Plan& plan = e.plan;
  const BodyPlan& p = e.bp(i);
  const int m = p.m();
  ProxRows::Body& b = rows.b[std::size_t(i)];
  std::vector<int> supportChildren;
  int own = m;
  for (int ch : p.children)
    if (e.bp(ch).onSupport) supportChildren.push_back(ch), own -= e.bp(ch).m();
  keyBelow[std::size_t(i)] = i;
  const bool link = own == 0 && supportChildren.size() == 1;  // no pair of rows meets here
  if (link && p.parent == 0) return;                          // nor above: the world does not move
  if (link && m > kMapColumns) {
    // T_i = B_ch T_ch, column by column; the columns stay at keyBelow.
    const int ch = supportChildren[0];
    const std::vector<Expr>& Tch = st.T[std::size_t(ch)];
    std::vector<Expr>& T = st.T[std::size_t(i)];
    T.assign(36, Expr());
    for (int c = 0; c < 6; ++c) {
      V6 col;
      if (Tch.empty()) col[std::size_t(c)] = 1.0;
      else for (int r = 0; r < 6; ++r) col[std::size_t(r)] = Tch[std::size_t(6 * r + c)];
      const V6 y = throughJoint(e, kin, art, ch, col);
      for (int r = 0; r < 6; ++r) T[std::size_t(6 * r + c)] = e.put(e.member(kT, i, 6, 6, r, c), y[std::size_t(r)]);
    }
    keyBelow[std::size_t(i)] = keyBelow[std::size_t(ch)];
    return;
  }
  for (int ch : supportChildren) {
    const BodyPlan& cp = e.bp(ch);
    const ProxRows::Body& from = rows.b[std::size_t(keyBelow[std::size_t(ch)])];
    for (int c = 0; c < cp.m(); ++c) {
      const V6 y = throughJoint(e, kin, art, ch, apply(cb, st.T[std::size_t(ch)], from.KA[std::size_t(c)]));
      const int col = cp.offsetInParent + c;
      for (int r = 0; r < 6; ++r)
        b.KA[std::size_t(col)][std::size_t(r)] = e.put(e.member(kKD, i, 6, m, r, col), y[std::size_t(r)]);
    }
  }
  if (link) return;
  // group[c]: -1 for an own row, else the support child whose subtree holds column c.
  std::vector<int> group(std::size_t(m), -1);
  for (int ch : supportChildren) {
    const BodyPlan& cp = e.bp(ch);
    for (int c = 0; c < cp.m(); ++c) group[std::size_t(cp.offsetInParent + c)] = ch;
  }
  const Sym& Phi = st.Phi[std::size_t(i)];
  const Expr mu = inverse ? cb.input("mu") : Expr();
  for (int c = 0; c < m; ++c) {
    bool needed = false;
    for (int a = 0; a <= c && !needed; ++a) needed = group[std::size_t(a)] < 0 || group[std::size_t(a)] != group[std::size_t(c)];
    if (!needed) continue;
    V6 w = mul(cb, Phi, b.KA[std::size_t(c)]);
    flatten(cb, w, "w");
    for (int a = 0; a <= c; ++a) {
      if (group[std::size_t(a)] >= 0 && group[std::size_t(a)] == group[std::size_t(c)]) continue;  // met below
      const int ra = p.subtreeRows[std::size_t(a)], rc = p.subtreeRows[std::size_t(c)];
      const Expr x = dot(cb, b.KA[std::size_t(a)], w);
      // delassus_inverse: mu [a == c] - mu^2 x (x of the penalised recursion).
      const Expr value = inverse ? (ra == rc ? mu : Expr()) - cb.mul(cb.mul(mu, mu), cb.flat(x)) : x;
      const Expr g = e.put(e.ws.member("Gd", plan.nc * (plan.nc + 1) / 2, Sym::index(plan.nc, ra, rc),
                                       inverse ? "(G + I/mu)^-1 (packed upper triangle, layout order)"
                                               : "G (packed upper triangle, layout order)"),
                           value);
      st.out[std::size_t(ra * plan.nc + rc)] = st.out[std::size_t(rc * plan.nc + ra)] = g;
    }
  }
}

}  // namespace

std::string emitDelassus(Emit& e, const ConstraintJoints& joints, bool inverse) {
  const Plan& plan = e.plan;
  const int N = e.model().numBodies();
  Kinematics kin = joints.kin;
  Articulated art = startElimination(kin);
  ConstraintOutputs st;
  st.Phi.assign(std::size_t(N), Sym());
  st.T.assign(std::size_t(N), {});
  std::vector<int> keyBelow(std::size_t(N), 0);
  st.out.assign(std::size_t(plan.nc * plan.nc), Expr());
  ProxRows rows;
  rows.b.resize(std::size_t(N));
  for (int i = 0; i < N; ++i) initOwnRows(e, i, rows);
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().art = &art;
  e.fn.live().rows = &rows;
  e.fn.live().cons = &st;
  e.fn.beginHost(inverse ? "dinv" : "delassus", joints.host);
  Expr hostMu;
  if (inverse) {
    hostMu = e.cb().define("mu", "s.mu", {}, {"s"});
    e.fn.setHostMu(hostMu);
  }
  // The schedule: the penalty mu_c = mu times c's factor (delassus_inverse),
  // and F out F at the end (docs/algorithms.md §4.4).
  storeActiveFactors(e, inverse ? "s.active" : "active");
  e.cb().line("constraint_joints(q, w);", {}, {"q", "w"});
  // No penalty right-hand side: the recursion reads the inertias only.
  const std::vector<std::vector<Expr>> noRhs = [&] {
    std::vector<std::vector<Expr>> k;
    for (const Constraint& c : e.sys.constraints) k.emplace_back(std::size_t(c.rows()));
    return k;
  }();
  e.fn.beginPass("eliminate", inverse ? "articulated inertias, the penalty mu K^T K at the constrained bodies"
                                      : "articulated inertias");
  for (int i = N - 1; i >= 1; --i) {
    e.fn.boundary(i);
    e.openBody(i, "eliminate:");
    eliminateBody(e, kin, i, inverse ? &noRhs : nullptr, art, false);
    e.cb().close();
  }
  if (plan.nc > 0) {
    e.fn.beginPass("phi", "forward: apparent inverse inertias Phi of the support");
    for (int i : plan.support) {
      e.fn.boundary(i);
      e.openBody(i, "apparent inverse inertia:");
      const Sym Phi = apparentInverseInertia(e, kin, art, st, i);
      Sym& out = st.Phi[std::size_t(i)];
      out = Sym(6);
      for (int k = 0; k < 21; ++k) out.packed(k) = e.putQ(kPhi, i, 21, k, Phi.packed(k));
      e.cb().close();
    }
    e.fn.beginPass("rows", "backward: the rows' force directions, each entry where its two rows meet");
    for (auto it = plan.support.rbegin(); it != plan.support.rend(); ++it) {
      e.fn.boundary(*it);
      e.openBody(*it, "rows meeting here:");
      rowsAt(e, kin, art, st, rows, keyBelow, *it, inverse);
      e.cb().close();
    }
  }
  // Pairs meeting only at the world, and rows on the world, stay 0 (G) or mu I (the inverse).
  e.fn.endPart();  // st is the host's now
  if (inverse)
    for (int r = 0; r < plan.nc; ++r)
      if (st.out[std::size_t(r * plan.nc + r)].isZero()) st.out[std::size_t(r * plan.nc + r)] = hostMu;
  scheduleOutput(e, st.out, plan.nc, true);
  copyOutput(e, inverse ? "Ginv" : "G", st.out);
  std::string text = e.fn.endHost(inverse ? std::vector<std::string>{"q", "s", "w", "Ginv"}
                                          : std::vector<std::string>{"q", "w", "G", "active"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

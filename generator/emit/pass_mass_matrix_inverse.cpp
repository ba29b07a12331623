// M(q)^-1 in O(n^2) without factoring M: ABA on the nv unit torques at once,
// with v = 0 and no gravity (docs/dynamics.md). Body i has dofs [s, s + n) and
// subtree dofs [s, e). Backward, leaves first, F_i[:, j] the unit-torque bias
// force (zero unless j is in i's subtree):
//   Minv(s, s) = D^-1; Minv(s, j) = -D^-1 S^T F_i[:, j] (s < j < e);
//   F_i[:, j] += U Minv(s, j); F_p[:, j] += X^T F_i[:, j]; IA_p += X^T Ia X.
// Forward, root first, for every column j >= s (the upper triangle):
//   a' = X A_p[:, j]; Minv(s, j) -= D^-1 U^T a'; A_i[:, j] = a' + S Minv(s, j).
// F_i and A_i share the member FA_<body> (the forces are last read before the
// accelerations are written). The forward pass writes each final Minv(s, j)
// into both triangles of the output; the rows that are final after the
// backward pass (the free flyer's, a child of the world's) are written from
// the members. The free flyer (always the root) uses the Cholesky factor of
// its 6 x 6 IA for D^-1, a planar joint (anywhere) that of its 3 x 3 D
// (backwardPicked, forwardPicked). Each one-dof body's columns go in loops
// over runs of one shape ("Column loops" below). Printed a second time for
// constrained_dynamics_derivatives (mass_matrix_inverse_factored, host minvf):
// after prox_pv of the same q, whose elimination left U, D^-1 and the Cholesky
// factors in the same members, its backward pass reads them and forms neither
// them nor the articulated inertias. The forward pass reads only members either
// backward pass writes: mass_matrix_inverse_forward, printed once, ends both.
// The generic counterpart:
// algorithms/mass_matrix_inverse.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <functional>
#include <utility>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

// Minv(r, c), r <= c, between the passes (the output is written by the forward pass).
std::string minvMember(Emit& e, int r, int c) {
  const int nv = e.plan.nv;
  return e.member("minv", nv * (nv + 1) / 2, Sym::index(nv, r, c), "M^-1 (upper triangle, by rows)");
}
// Its slot in a loop over the columns c + j of row r.
std::string minvLoopSlot(Emit& e, int r, int c) {
  const int nv = e.plan.nv;
  return e.ws.loopSlot("minv", nv * (nv + 1) / 2, Sym::index(nv, r, c), "M^-1 (upper triangle, by rows)");
}

// IA_p += X^T (IA - U D^-1 U^T) X for a one-dof body (v = 0: no bias).
void passInertia(Emit& e, const Kinematics& kin, int i, Articulated& art) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  V6 UD;
  for (int r = 0; r < 6; ++r) UD[std::size_t(r)] = cb.flat(cb.mul(b.U[0][std::size_t(r)], b.Dinv), "UD");
  Sym Ia(6);
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) Ia(r, c) = b.IA(r, c) - cb.mul(UD[std::size_t(r)], b.U[0][std::size_t(c)]);
  if (const int along = axisComponent(p); along >= 0)
    for (int k = 0; k < 6; ++k) Ia(along, k) = Expr();  // Ia S = 0
  flatten(cb, Ia, "Ia");
  const Sym dI = e.inertiaToParent(kin.b[std::size_t(i)], Ia);
  Articulated::Body& par = art.b[std::size_t(p.parent)];
  for (int k = 0; k < 21; ++k)
    if (!dI.packed(k).isZero()) par.IA.packed(k) = e.putQ(kIA, p.parent, 21, k, par.IA.packed(k) + dI.packed(k));
}

// Column loops. Body i treats every column j with the same coefficients (its
// transform, U, D^-1): only which members it reads and writes differ, so a run
// of adjacent columns whose entries have one shape is one loop over j
// (column_loops.cpp), and each pass is O(n) code instead of O(n^2) (forward) or
// O(n depth) (backward); the compiler vectorises across columns
// (docs/dynamics.md, "mass_matrix_inverse").

// Column j (s < j < dofEnd, the subtree's) of a one-dof body: Minv(s, j) =
// -D^-1 S^T F_i[:, j], and F_p[:, j] += X^T (F_i[:, j] + U Minv(s, j)) (Fp:
// F_p[:, j] before). Stores into minvOut and fpOut(r) (in a loop, column j's
// slots); returns Minv(s, j) and F_p[:, j] with the rows it wrote.
struct Accumulated {
  V6 value;
  std::array<bool, 6> stored{};
};
std::pair<Expr, Accumulated> eliminateColumn(Emit& e, const Kinematics::Body& kb, const Articulated::Body& b,
                                             bool toParent, const V6& F, const V6& Fp, bool loop,
                                             const std::string& minvOut,
                                             const std::function<std::string(int)>& fpOut) {
  CodeBuilder& cb = e.cb();
  const Expr x = e.put(minvOut, -cb.mul(b.Dinv, cb.flat(dot(cb, kb.S[0], F))));
  Accumulated out{Fp, {}};
  if (!toParent) return {x, out};
  V6 f;
  for (int r = 0; r < 6; ++r) f[std::size_t(r)] = F[std::size_t(r)] + cb.mul(b.U[0][std::size_t(r)], x);
  flatten(cb, f, "f");
  const V6 dp = e.forceToParent(kb, f);
  for (int r = 0; r < 6; ++r)
    if (!dp[std::size_t(r)].isZero()) {
      const Expr sum = Fp[std::size_t(r)] + dp[std::size_t(r)];
      out.value[std::size_t(r)] = loop ? e.put(fpOut(r), sum) : e.keep(fpOut(r), sum);
      out.stored[std::size_t(r)] = true;
    }
  return {x, out};
}

// `factored`: art holds U and D^-1 of this q already (prox_pv's elimination
// left them in the same members), so neither they nor the articulated
// inertias passed up are formed again.
void backwardOneDof(Emit& e, const Kinematics& kin, int i, Articulated& art, JointSpace& js, bool factored) {
  Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v, nv = e.plan.nv;
  const bool toParent = p.parent != 0;  // else nothing passes on: the forward pass reads only Minv
  std::vector<V6>& F = js.FA[std::size_t(i)];
  std::vector<V6>& Fp = js.FA[std::size_t(std::max(p.parent, 0))];
  e.fn.boundary(i);
  e.openBody(i, "eliminate");
  {
    CodeBuilder& cb = e.cb();
    if (!factored) {
      const V6& S = kb.S[0];
      V6 U = mul(cb, b.IA, S);
      b.U.assign(1, V6{});
      for (int r = 0; r < 6; ++r) b.U[0][std::size_t(r)] = e.keepQ(kU, i, 6, r, U[std::size_t(r)]);
      const Expr D = cb.flat(dot(cb, S, b.U[0]), "D");
      if (D.isConstant()) {  // folded as in pass_aba_eliminate.cpp: correctly rounded in the solver's Scalar
        b.Dinv = e.plan.scalar == ScalarType::Float ? Expr(double(1.0f / float(D.constant()))) : Expr(1.0 / D.constant());
      } else {
        b.Dinv = cb.storeRaw(e.member(kDinv, i, 0, 0), cb.literal(1.0) + " / " + cb.print(D), {D}, Ops::divisions(1));
      }
    }
    js.upper(s, s) = b.Dinv;
    if (toParent) {  // the body's own column: F_i[:, s] = 0, Minv(s, s) = D^-1
      const V6 dp = e.forceToParent(kb, scale(cb, b.Dinv, b.U[0]));
      for (int r = 0; r < 6; ++r)
        if (!dp[std::size_t(r)].isZero())
          Fp[std::size_t(s)][std::size_t(r)] =
              e.keepQ(kFA, p.parent, 6, nv, r, s, Fp[std::size_t(s)][std::size_t(r)] + dp[std::size_t(r)]);
      if (!factored) passInertia(e, kin, i, art);
    }
  }
  e.cb().close();
  // The subtree's columns: F_i[:, j], then F_p[:, j] (it accumulates).
  const auto inputs = [&](int j) {
    std::vector<Expr> in = entries(F[std::size_t(j)]);
    if (toParent)
      for (const Expr& x : Fp[std::size_t(j)]) in.push_back(x);
    return in;
  };
  std::vector<int> cols;
  for (int j = s + 1; j < e.bp(i).dofEnd; ++j) cols.push_back(j);
  const auto sameShape = [&](int k, int k0) { return oneShape(e.cb(), inputs, k, k0); };
  for (const auto& run : columnRuns(cols, sameShape)) {
    const int k0 = run.first, len = run.second;  // named: lambdas capture them (C++17)
    openColumns(e, p.ident, k0, len, fmt::format("body {} '{}', unit-torque forces,", i, p.ident));
    CodeBuilder& cb = e.cb();  // after openColumns: it may have started a new part
    if (len == 1) {
      const auto [x, fp] = eliminateColumn(e, kb, b, toParent, F[std::size_t(k0)], Fp[std::size_t(k0)], false,
                                           minvMember(e, s, k0),
                                           [&](int r) { return e.member(kFA, p.parent, 6, nv, r, k0); });
      js.upper(s, k0) = x;
      Fp[std::size_t(k0)] = fp.value;
      e.cb().close();
      continue;
    }
    const std::vector<Expr> in = loopReads(cb, inputs(k0));
    const std::string minvLoop = minvLoopSlot(e, s, k0);
    const auto [x, fp] = eliminateColumn(e, kb, b, toParent, toV6(in), toParent ? toV6(in, 6) : zero6(), true, minvLoop,
                                         [&](int r) { return e.loopSlot(kFA, p.parent, 6, nv, r, k0); });
    e.cb().close();
    // After the loop each column's slots hold new values: read them by their own names.
    for (int k = k0; k < k0 + len; ++k) {
      js.upper(s, k) = x.isConstant() ? x : cb.refresh(minvMember(e, s, k));
      for (int r = 0; r < 6; ++r)
        if (toParent && fp.stored[std::size_t(r)])
          Fp[std::size_t(k)][std::size_t(r)] = fp.value[std::size_t(r)].isConstant()
                                                    ? fp.value[std::size_t(r)]
                                                    : cb.refresh(e.member(kFA, p.parent, 6, nv, r, k));
    }
  }
}

// The free flyer at the root: D^-1 = IA^-1 through its Cholesky factor (factored:
// the one art holds).
void backwardFreeFlyer(Emit& e, int i, Articulated& art, JointSpace& js, bool factored) {
  Articulated::Body& b = art.b[std::size_t(i)];
  const int s = e.bp(i).idx_v;
  const auto Lname = [&](int r, int c) { return e.member(kL, i, 21, Sym::index(6, r, c)); };
  const auto invName = [&](int r) { return e.member(kLinv, i, 6, r); };
  e.fn.boundary(i);
  e.openBody(i, "eliminate");
  Cholesky ch = factored ? Cholesky{b.L, b.Linv} : cholesky(e, b.IA, Expr(), Lname, invName);
  const auto solve = [&](const std::vector<Expr>& rhs) {
    return choleskySolve(e.cb(), ch.L, ch.inv, rhs);
  };
  for (int c = 0; c < 6; ++c) {
    std::vector<Expr> unit(6);
    unit[std::size_t(c)] = Expr(1.0);
    const std::vector<Expr> x = solve(unit);
    for (int r = 0; r <= c; ++r) js.upper(s + r, s + c) = e.put(minvMember(e, s + r, s + c), x[std::size_t(r)]);
  }
  e.cb().close();
  // The subtree's columns, Minv(s.., j) = -IA^-1 F[:, j], a loop per run of one shape.
  const std::vector<V6>& F = js.FA[std::size_t(i)];
  const auto inputs = [&](int j) { return entries(F[std::size_t(j)]); };
  std::vector<int> cols;
  for (int j = s + 6; j < e.bp(i).dofEnd; ++j) cols.push_back(j);
  const auto sameShape = [&](int k, int k0) { return oneShape(e.cb(), inputs, k, k0); };
  for (const auto& run : columnRuns(cols, sameShape)) {
    const int k0 = run.first, len = run.second;  // named: lambdas capture them (C++17)
    openColumns(e, e.bp(i).ident, k0, len, fmt::format("body {} '{}', unit-torque forces,", i, e.bp(i).ident));
    CodeBuilder& cb = e.cb();  // after openColumns: it may have started a new part
    // The factor is in members: read them in this part (a local Cholesky is not in the Live state).
    for (int r = 0; r < 6; ++r) {
      if (!ch.inv[std::size_t(r)].isConstant()) ch.inv[std::size_t(r)] = cb.member(invName(r));
      for (int c = 0; c <= r; ++c)
        if (!ch.L(r, c).isConstant()) ch.L(r, c) = cb.member(Lname(r, c));
    }
    const bool loop = len > 1;
    const std::vector<Expr> x = solve(loop ? loopReads(cb, inputs(k0)) : inputs(k0));
    std::array<Expr, 6> stored;
    for (int r = 0; r < 6; ++r) {
      const std::string slot = loop ? minvLoopSlot(e, s + r, k0) : minvMember(e, s + r, k0);
      stored[std::size_t(r)] = e.put(slot, -x[std::size_t(r)]);
    }
    e.cb().close();
    for (int k = k0; k < k0 + len; ++k)
      for (int r = 0; r < 6; ++r) {
        const Expr& v = stored[std::size_t(r)];
        js.upper(s + r, k) = !loop || v.isConstant() ? v : cb.refresh(minvMember(e, s + r, k));
      }
  }
}

// Minv(row, j) = Minv(j, row) = x in the output, for column k0, or in a loop
// (`loop`) for column k0 + j.
void writeOut(Emit& e, int row, int k0, bool loop, const Expr& value) {
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  const Expr x = cb.flat(value, "m");
  const std::string v = cb.print(x);
  if (loop) {
    cb.line(fmt::format("Minv[{} + j] = {};", row * nv + k0, v), {x}, {"Minv"});
    cb.line(fmt::format("Minv[{} + {} * j] = {};", k0 * nv + row, nv, v), {x}, {"Minv"});
    return;
  }
  cb.line(fmt::format("Minv[{}] = {};", row * nv + k0, v), {x}, {"Minv"});
  if (k0 != row) cb.line(fmt::format("Minv[{}] = {};", k0 * nv + row, v), {x}, {"Minv"});
}

// A planar joint (pass_aba_eliminate.cpp, eliminatePicked): S picks the
// components sel, U = IA S is three columns of IA and D = S^T U their 3 x 3
// block, factored (L L^T). Minv(s.., s..) = D^-1, Minv(s.., j) = -D^-1 S^T
// F_i[:, j] for the subtree's columns, F_p[:, j] += X^T (F_i[:, j] + U
// Minv(s.., j)) and IA_p += X^T (IA - U D^-1 U^T) X. A planar joint is rare
// (a mobile base, once per robot): its columns are printed one by one.
void backwardPicked(Emit& e, const Kinematics& kin, int i, Articulated& art, JointSpace& js, bool factored) {
  Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v, nv = e.plan.nv;
  const bool toParent = p.parent != 0;
  std::vector<V6>& F = js.FA[std::size_t(i)];
  std::vector<V6>& Fp = js.FA[std::size_t(std::max(p.parent, 0))];
  e.fn.boundary(i);
  e.openBody(i, "eliminate");
  CodeBuilder& cb = e.cb();
  if (!factored) factorPicked(e, i, b.IA, b);
  const std::vector<int> sel = pickedComponents(p.jointClass);
  const int n = int(sel.size());
  const auto solve = [&](const std::vector<Expr>& rhs) { return choleskySolve(cb, b.L, b.Linv, rhs); };  // D^-1 rhs
  // Passes one column f of the subtree's forces on to the parent: F_p[:, j] += X^T f.
  const auto passOn = [&](int j, V6 f) {
    flatten(cb, f, "f");
    const V6 dp = e.forceToParent(kb, f);
    for (int r = 0; r < 6; ++r)
      if (!dp[std::size_t(r)].isZero())
        Fp[std::size_t(j)][std::size_t(r)] =
            e.keepQ(kFA, p.parent, 6, nv, r, j, Fp[std::size_t(j)][std::size_t(r)] + dp[std::size_t(r)]);
  };
  // Columns s + c of D^-1: the block Minv(s.., s..), and (its own columns' F_i = 0) U D^-1 e_c on.
  for (int c = 0; c < n; ++c) {
    std::vector<Expr> unit(static_cast<std::size_t>(n));
    unit[std::size_t(c)] = Expr(1.0);
    std::vector<Expr> x = solve(unit);
    for (Expr& v : x) v = cb.flat(v, "m");
    for (int r = 0; r <= c; ++r) js.upper(s + r, s + c) = e.put(minvMember(e, s + r, s + c), x[std::size_t(r)]);
    if (!toParent) continue;
    V6 f = zero6();
    for (int d = 0; d < n; ++d) f = add(f, scale(cb, x[std::size_t(d)], b.U[std::size_t(d)]));
    passOn(s + c, f);
  }
  if (toParent && !factored) {  // IA_p += X^T (IA - U D^-1 U^T) X
    const Sym dI = e.inertiaToParent(kb, reducedPicked(cb, b.IA, b, sel));
    Articulated::Body& par = art.b[std::size_t(p.parent)];
    for (int k = 0; k < 21; ++k)
      if (!dI.packed(k).isZero()) par.IA.packed(k) = e.putQ(kIA, p.parent, 21, k, par.IA.packed(k) + dI.packed(k));
  }
  // The subtree's columns: Minv(s.., j) = -D^-1 S^T F_i[:, j], then F_i[:, j] + U Minv(s.., j) on.
  for (int j = s + n; j < p.dofEnd; ++j) {
    std::vector<Expr> rhs(static_cast<std::size_t>(n));
    for (int d = 0; d < n; ++d) rhs[std::size_t(d)] = F[std::size_t(j)][std::size_t(sel[std::size_t(d)])];
    std::vector<Expr> x = solve(rhs);
    for (int d = 0; d < n; ++d) {
      x[std::size_t(d)] = e.put(minvMember(e, s + d, j), -x[std::size_t(d)]);
      js.upper(s + d, j) = x[std::size_t(d)];
    }
    if (!toParent) continue;
    V6 f = F[std::size_t(j)];
    for (int d = 0; d < n; ++d) f = add(f, scale(cb, x[std::size_t(d)], b.U[std::size_t(d)]));
    passOn(j, f);
  }
  cb.close();
}

// Forward, a planar joint: for every column j >= s, a' = X A_p[:, j] (zero at
// the root), x = Minv(s.., j) - D^-1 U^T a', Minv(s + d, j) = x_d written out
// for s + d <= j, and A_i[:, j] = a' + S x.
void forwardPicked(Emit& e, const Kinematics& kin, int i, const Articulated& art, JointSpace& js) {
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v, nv = e.plan.nv;
  const bool store = !p.children.empty();
  const Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const std::vector<int> sel = pickedComponents(p.jointClass);
  const int n = int(sel.size());
  std::vector<V6>& A = js.FA[std::size_t(i)];
  e.fn.boundary(i);
  e.openBody(i, "accelerate");
  CodeBuilder& cb = e.cb();
  for (int j = s; j < nv; ++j) {
    std::vector<Expr> x(static_cast<std::size_t>(n));
    for (int d = 0; d < n; ++d) x[std::size_t(d)] = js.upper(s + d, j);
    V6 a = zero6();
    if (p.parent != 0) {
      a = e.motionToChild(kb, js.FA[std::size_t(p.parent)][std::size_t(j)]);
      flatten(cb, a, "t");
      std::vector<Expr> Ua(static_cast<std::size_t>(n));
      for (int d = 0; d < n; ++d) Ua[std::size_t(d)] = cb.flat(dot(cb, b.U[std::size_t(d)], a));
      const std::vector<Expr> y = choleskySolve(cb, b.L, b.Linv, Ua);
      for (int d = 0; d < n; ++d) x[std::size_t(d)] = cb.flat(x[std::size_t(d)] - y[std::size_t(d)], "m");
    }
    for (int d = 0; d < n && s + d <= j; ++d) writeOut(e, s + d, j, false, x[std::size_t(d)]);
    if (!store) continue;
    V6 Aj = a;
    for (int d = 0; d < n; ++d) Aj[std::size_t(sel[std::size_t(d)])] = Aj[std::size_t(sel[std::size_t(d)])] + x[std::size_t(d)];
    for (int r = 0; r < 6; ++r) A[std::size_t(j)][std::size_t(r)] = e.keepQ(kFA, i, 6, nv, r, j, Aj[std::size_t(r)]);
  }
  cb.close();
}

// A row whose entries Minv(row, j), j >= from, are final in js (the free
// flyer's after the backward pass, a child of the world's), into the output.
void writeRow(Emit& e, int i, int row, int from, const JointSpace& js) {
  const int nv = e.plan.nv;
  const auto inputs = [&](int j) { return std::vector<Expr>{js.upper(row, j)}; };
  std::vector<int> cols;
  for (int j = from; j < nv; ++j) cols.push_back(j);
  const auto sameShape = [&](int k, int k0) { return oneShape(e.cb(), inputs, k, k0); };
  for (const auto& run : columnRuns(cols, sameShape)) {
    const int k0 = run.first, len = run.second;  // named: lambdas capture them (C++17)
    openColumns(e, fmt::format("{}_r{}", e.bp(i).ident, row), k0, len,
                fmt::format("body {} '{}', M^-1 row {},", i, e.bp(i).ident, row));
    const bool loop = len > 1;
    writeOut(e, row, k0, loop, loop ? loopReads(e.cb(), inputs(k0))[0] : inputs(k0)[0]);
    e.cb().close();
  }
}

// x = Minv(s, j) - D^-1 U^T a' with a' = X A_p[:, j], into the output
// (nothing reads it after this pass); A_i[:, j] = a' + S x, stored into
// `aOut(r)` (in a loop, column j's slots) unless constant, and outside a loop
// unless +-(a member) already.
V6 accelerateColumn(Emit& e, const Kinematics::Body& kb, const Articulated::Body& b, int s, int k0, const V6& Ap,
                    const Expr& minv, bool store, bool loop, const std::function<std::string(int)>& aOut) {
  CodeBuilder& cb = e.cb();
  V6 a = e.motionToChild(kb, Ap);
  flatten(cb, a, "t");
  const Expr x = cb.flat(minv - cb.mul(b.Dinv, cb.flat(dot(cb, b.U[0], a))), "m");
  writeOut(e, s, k0, loop, x);
  V6 A = zero6();
  if (!store) return A;
  const V6 Aj = add(a, scale(cb, x, kb.S[0]));
  for (int r = 0; r < 6; ++r)
    A[std::size_t(r)] = loop ? e.put(aOut(r), Aj[std::size_t(r)]) : e.keep(aOut(r), Aj[std::size_t(r)]);
  return A;
}

void forwardBody(Emit& e, const Kinematics& kin, int i, const Articulated& art, JointSpace& js) {
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v, nv = e.plan.nv;
  const bool store = !p.children.empty();  // A_i is read by the children only
  std::vector<V6>& A = js.FA[std::size_t(i)];
  if (p.jointClass == JointClass::FreeFlyer) {  // the root: a' = 0, A = S Minv(s.., j) with S = I
    for (int r = 0; r < 6; ++r) writeRow(e, i, s + r, s + r, js);
    for (int j = s; j < nv; ++j)
      for (int r = 0; r < 6; ++r) A[std::size_t(j)][std::size_t(r)] = store ? js.upper(s + r, j) : Expr();
    return;
  }
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  if (p.parent == 0) {  // a' = 0: Minv(s, j) is final, A = S Minv(s, j)
    writeRow(e, i, s, s, js);
    for (int j = s; j < nv && store; ++j) {
      const V6 Aj = scale(e.cb(), js.upper(s, j), kb.S[0]);  // +-(a member): no statement
      for (int r = 0; r < 6; ++r) A[std::size_t(j)][std::size_t(r)] = e.keepQ(kFA, i, 6, nv, r, j, Aj[std::size_t(r)]);
    }
    return;
  }
  const Articulated::Body& b = art.b[std::size_t(i)];
  const std::vector<V6>& Ap = js.FA[std::size_t(p.parent)];
  // Column j's inputs: A_p[:, j], then Minv(s, j) from the backward pass.
  const auto inputs = [&](int j) {
    std::vector<Expr> in = entries(Ap[std::size_t(j)]);
    in.push_back(js.upper(s, j));
    return in;
  };
  std::vector<int> cols;
  for (int j = s; j < nv; ++j) cols.push_back(j);
  const auto sameShape = [&](int k, int k0) { return oneShape(e.cb(), inputs, k, k0); };
  for (const auto& run : columnRuns(cols, sameShape)) {
    const int k0 = run.first, len = run.second;  // named: lambdas capture them (C++17)
    openColumns(e, p.ident, k0, len, fmt::format("body {} '{}', accelerations,", i, p.ident));
    CodeBuilder& cb = e.cb();  // after openColumns: it may have started a new part
    const bool loop = len > 1;
    const std::vector<Expr> in = loop ? loopReads(cb, inputs(k0)) : inputs(k0);
    const V6 Aj = accelerateColumn(e, kb, b, s, k0, toV6(in), in[6], store, loop, [&](int r) {
      return loop ? e.loopSlot(kFA, i, 6, nv, r, k0) : e.member(kFA, i, 6, nv, r, k0);
    });
    e.cb().close();
    // After a loop each column's slots hold new values: read them by their own names.
    for (int k = k0; k < k0 + len; ++k)
      for (int r = 0; r < 6; ++r)
        A[std::size_t(k)][std::size_t(r)] = !loop || !store || Aj[std::size_t(r)].isConstant()
                                                ? Aj[std::size_t(r)]
                                                : cb.refresh(e.member(kFA, i, 6, nv, r, k));
  }
}

}  // namespace

std::string emitMassMatrixInverse(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms,
                                  const Articulated* eliminated, std::string* forwardText) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size());
  const bool factored = eliminated != nullptr;
  // IA = I, pA = 0 (the transforms pass sets no bias), or the elimination's factors.
  Articulated art = factored ? *eliminated : startElimination(kin);
  JointSpace js;
  js.upper = Sym(plan.nv);
  js.FA.assign(std::size_t(N), std::vector<V6>(std::size_t(plan.nv), zero6()));
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().art = &art;
  e.fn.live().js = &js;
  e.fn.beginHost(factored ? "minvf" : "minv", afterTransforms);
  e.fn.beginPass("backward", factored ? "backward: the unit-torque forces, leaves first (U, D^-1 as the elimination left them)"
                                      : "backward: D^-1 and the unit-torque forces, leaves first");
  for (int i = N - 1; i >= 1; --i) {
    if (e.bp(i).jointClass == JointClass::FreeFlyer) backwardFreeFlyer(e, i, art, js, factored);
    else if (e.bp(i).jointClass == JointClass::Planar) backwardPicked(e, kin, i, art, js, factored);
    else backwardOneDof(e, kin, i, art, js, factored);
  }
  // The forward pass reads only what either backward pass leaves in the same
  // members (U, D^-1, the factors, the unit-torque forces, Minv's entries so
  // far): one print, mass_matrix_inverse_forward, called by both variants.
  e.fn.endPart();
  e.cb().line("mass_matrix_inverse_forward(w, Minv);", {}, {"w", "Minv"});
  std::string text = e.fn.endHost({"q", "w", "Minv"});
  if (forwardText != nullptr) {
    e.fn.beginHost("minv_forward", e.fn.lastHost());
    e.fn.beginPass("", "forward: the unit-torque accelerations, the upper triangle of M^-1");
    for (int i = 1; i < N; ++i) {
      if (e.bp(i).jointClass == JointClass::Planar) forwardPicked(e, kin, i, art, js);
      else forwardBody(e, kin, i, art, js);
    }
    *forwardText = e.fn.endHost({"w", "Minv"});
  }
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

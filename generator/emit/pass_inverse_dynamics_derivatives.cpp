// The derivatives of inverse dynamics, tau = RNEA(q, v, qdd) + J^T lambda, at
// fixed qdd and lambda, in the world frame (Carpentier and Mansard's form;
// docs/derivatives.md sections 2b and 5): tangent_sweep(q, v, qdd, lambda, w,
// dtau_dq, dtau_dv), on the kinematics state in w. Every body's quantities are
// moved to world axes once, in blocks with the model's constants folded:
//   forward, root first:    oM_i = oM_p liM_i, ov_i, oa_i (oa_0 = -a_g), oS_i,
//                           oI_i, of_i = oI_i oa_i + ov_i x* oI_i ov_i (+ K^T lambda), and
//                           B_i = -oI_i (ov_i x) + H(oI_i ov_i) + (ov_i x*) oI_i, whose
//                           blocks are [0, -2 [hl]x; 0, Baa] (hl: the linear momentum);
//   backward, leaves first: the subtree sums Ic, HL, Baa, F, and per dof (s = oS e_k,
//                           l the parent) u = s x ov_l, c = -s x oa_l + u x ov_l,
//                           w = -s x (ov_l + ov_j), Pq = s x* F_j + Ic_j c - Bc_j u,
//                           Pv = Ic_j w + Bc_j s, IS = Ic_j s, BS = Bc_j^T s (angular part),
// into component-major per-dof arrays; then every (dof r, dof c of r's path) pair
// is a few six-vector products in loops over constant tables (world_frame_rows,
// world_frame_columns, printed by assemble.cpp):
//   dtau_dq[r][c] = IS_r . C_c - BS_r . U_c,   dtau_dv[r][c] = IS_r . W_c + BS_r . oS_c,
//   for c a strict ancestor's dof  dtau_dq[c][r] = oS_c . Pq_r,  dtau_dv[c][r] = oS_c . Pv_r.
// O(N) blocks and O(N d) products in two loops, where a body-frame tangent
// sweep carries every column through every body below its joint (O(N d)
// blocks; docs/derivatives.md section 5 has the measurements). The per-dof
// arrays (s, u, c, w) and the world placements and velocities stay in the
// workspace for constrained_dynamics_derivatives' constraint rows. The generic
// counterpart: algorithms/rnea_derivatives_world.cpp.
// The file also holds forward_dynamics_derivatives and the helpers the derivative
// functions share (the sparse patterns, the copies, the products with M^-1).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "emit/passes.hpp"
#include "model/error.hpp"

namespace proxgen::emit {
namespace {

constexpr Quantity kWR{"oRd", "world rotation (world-frame derivatives)"},
    kWP{"opd", "world position (world-frame derivatives)"}, kWV{"ovd", "velocity in world axes"},
    kWA{"oad", "acceleration in world axes (gravity-shifted)"},
    kWI{"oIc", "composite inertia in world axes about the world origin: h = m c, then I (upper triangle)"},
    kWH{"oHc", "composite linear momentum in world axes (B's linear-angular block is -2 [HL]x)"},
    kWB{"oBc", "composite B's angular block (3 x 3, row-major)"}, kWF{"oFc", "subtree force in world axes"};

// The per-dof arrays the pairs' loop reads, component-major ([6][nv]; BS [3][nv]):
// column k of each is dof k's six-vector, and a run of dofs is contiguous in every row.
enum ColumnArray { kS, kU, kC, kW, kPq, kPv, kIS, kBS, kColumnArrayCount };
struct ColumnArrayInfo {
  const char* name;
  int rows;
  const char* what;
};
constexpr ColumnArrayInfo kColumnArrays[] = {
    {"oS", 6, "joint axes in world axes (column k: dof k)"},
    {"oU", 6, "u = s x ov_parent per dof"},
    {"oC", 6, "c = -s x oa_parent + u x ov_parent per dof"},
    {"oW", 6, "w = -s x (ov_parent + ov) per dof"},
    {"oPq", 6, "d F / dq of the joint's subtree per dof"},
    {"oPv", 6, "d F / dqd of the joint's subtree per dof"},
    {"oIS", 6, "Ic s per dof"},
    {"oBS", 3, "Bc^T s per dof (its angular part: the linear one is zero)"}};

// A stored value: a generation-time constant, or the member it was stored to.
using Slots = std::vector<TangentSlot>;

// x into body's member of quantity qy (`store`), or the slots of values putQ
// stored there already.
Slots keep(Emit& e, const Quantity& qy, int body, const std::vector<Expr>& x, bool store = true) {
  return slotsOf(e, x, [&](int k) { return e.member(qy, body, int(x.size()), k); }, store);
}

std::vector<Expr> read(CodeBuilder& cb, const Slots& s) { return load(cb, s); }

V6 read6(CodeBuilder& cb, const Slots& s) { return toV6(read(cb, s)); }
V3 read3(CodeBuilder& cb, const Slots& s) {
  const std::vector<Expr> x = read(cb, s);
  return {x[0], x[1], x[2]};
}

// child -> parent (world): [R l + p x R a; R a].
V6 actMotion(CodeBuilder& cb, const XSym& X, const V6& m) {
  V3 a = rotate(cb, X.R, ang(m));
  for (Expr& x : a) x = cb.flat(x);
  V3 l = rotate(cb, X.R, lin(m));
  const V3 pxa = cross(cb, X.p, a);
  for (std::size_t i = 0; i < 3; ++i) l[i] += pxa[i];
  return stack(l, a);
}

// The rigid inertia's product [m x_l - h x x_a; h x x_l + I x_a] (symbolic.hpp, Rigid).
V6 rigidMul(CodeBuilder& cb, const Rigid& r, const V6& x) {
  const V3 hxa = cross(cb, r.h, ang(x)), hxl = cross(cb, r.h, lin(x));
  V6 y;
  for (std::size_t i = 0; i < 3; ++i) {
    y[i] = cb.mul(r.m, x[i]) - hxa[i];
    Expr s = hxl[i];
    for (std::size_t j = 0; j < 3; ++j) s += cb.mul(r.I(int(i), int(j)), x[3 + j]);
    y[3 + i] = s;
  }
  return y;
}

// B's angular block: -[hm]x[v]x - [v]x[hm]x - I [w]x + [w]x I - [ha]x (docs/derivatives.md
// section 5: with hl = m v - hm x w, B's other blocks are 0, -2 [hl]x (linear-angular) and 0).
M3 angularBlockOfB(CodeBuilder& cb, const Rigid& r, const V6& ov, const V6& h) {
  const V3 v = lin(ov), w = ang(ov);
  Expr hv;
  for (std::size_t k = 0; k < 3; ++k) hv += cb.mul(r.h[k], v[k]);
  hv = cb.flat(hv);
  const M3 W = skewOf(w), Ha = skewOf(ang(h));
  M3 B;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const std::size_t ui = std::size_t(i), uj = std::size_t(j);
      Expr x = -(cb.mul(v[ui], r.h[uj]) + cb.mul(r.h[ui], v[uj])) - Ha[std::size_t(3 * i + j)];
      if (i == j) x += 2.0 * hv;
      for (int k = 0; k < 3; ++k) {
        const Expr& wkj = W[std::size_t(3 * k + j)];
        const Expr& wik = W[std::size_t(3 * i + k)];
        if (!wkj.isZero()) x -= cb.mul(r.I(i, k), wkj);
        if (!wik.isZero()) x += cb.mul(wik, r.I(k, j));
      }
      B[std::size_t(3 * i + j)] = x;
    }
  return B;
}

// Bc x = [-2 HL x x_a; Baa x_a].
V6 applyB(CodeBuilder& cb, const V3& HL, const M3& Baa, const V6& x) {
  const V3 t = cross(cb, HL, ang(x));
  const V3 a = rotate(cb, Baa, ang(x));  // any 3 x 3 times a vector
  return {-2.0 * t[0], -2.0 * t[1], -2.0 * t[2], a[0], a[1], a[2]};
}

struct World {
  std::vector<Slots> oR, op, ov, oa, Ic, HL, Baa, F;  // per body (Ic: h then I)
  std::vector<std::array<Slots, kColumnArrayCount>> col;  // per dof: what each array holds
  std::vector<double> mass;  // per body, then of its subtree: a constant of the model
};

// Column k of a component-major array: stored in full (the loop reads every entry).
Slots storeColumn(Emit& e, int array, int k, const std::vector<Expr>& x) {
  const ColumnArrayInfo& a = kColumnArrays[array];
  Slots s(std::size_t(a.rows));
  for (std::size_t r = 0; r < s.size(); ++r) {
    const std::string name = e.ws.member(a.name, a.rows, e.plan.nv, int(r), k, a.what);
    e.cb().store(name, x[r]);
    if (x[r].isConstant())
      s[r].value = x[r];  // read back as the constant it is
    else
      s[r].name = name;
  }
  return s;
}

std::vector<Expr> entriesOf(const Rigid& r) {
  std::vector<Expr> x(r.h.begin(), r.h.end());
  for (int k = 0; k < r.I.packedSize(); ++k) x.push_back(r.I.packed(k));
  return x;
}

Rigid rigidFrom(const Expr& m, const std::vector<Expr>& x) {
  Rigid r;
  r.m = m;
  for (std::size_t k = 0; k < 3; ++k) r.h[k] = x[k];
  for (int k = 0; k < r.I.packedSize(); ++k) r.I.packed(k) = x[std::size_t(3 + k)];
  return r;
}

V6 neg(const V6& x) { return sub(zero6(), x); }

void forward(Emit& e, Kinematics& kin, bool withLambda, World& W) {
  const Plan& plan = e.plan;
  e.fn.beginPass("forward", "forward: world placements, ov, oa, oS, oI, of and B of every body");
  for (int i : plan.sweep) {
    Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    const std::size_t b = std::size_t(i), par = std::size_t(p.parent);
    e.fn.boundary(i);
    e.openBody(i, "world forward");
    CodeBuilder& cb = e.cb();
    // The world placement: stored, and carried to the children in kin (Live).
    XSym oM = compose(cb, kb.XT, kb.XJ);
    V6 oap = e.rootAcceleration();
    if (p.parent > 0) {
      oM = compose(cb, kin.b[par].oM, oM);
      oap = read6(cb, W.oa[par]);
    }
    for (int k = 0; k < 9; ++k) oM.R[std::size_t(k)] = e.putQ(kWR, i, 9, k, oM.R[std::size_t(k)]);
    for (int k = 0; k < 3; ++k) oM.p[std::size_t(k)] = e.putQ(kWP, i, 3, k, oM.p[std::size_t(k)]);
    kb.oM = oM;
    W.oR[b] = keep(e, kWR, i, std::vector<Expr>(oM.R.begin(), oM.R.end()), false);
    W.op[b] = keep(e, kWP, i, std::vector<Expr>(oM.p.begin(), oM.p.end()), false);
    V6 ov = actMotion(cb, oM, kb.v);
    flatten(cb, ov, "ov");
    V6 x = kb.c;
    for (int d = 0; d < p.nv; ++d)
      x = add(x, scale(cb, cb.input(fmt::format("qdd[{}]", p.idx_v + d)), kb.S[std::size_t(d)]));
    flatten(cb, x, "ax");
    V6 oa = add(oap, actMotion(cb, oM, x));
    flatten(cb, oa, "oa");
    W.ov[b] = keep(e, kWV, i, entries(ov));
    W.oa[b] = keep(e, kWA, i, entries(oa));
    for (int d = 0; d < p.nv; ++d)
      W.col[std::size_t(p.idx_v + d)][kS] = storeColumn(e, kS, p.idx_v + d, entries(actMotion(cb, oM, kb.S[std::size_t(d)])));
    const Rigid own = rigidOf(kb.IA);
    W.mass[b] = own.m.constant();
    Rigid oI = rigidToParent(cb, oM, own);
    for (Expr& y : oI.h) y = cb.flat(y, "hm");
    for (int k = 0; k < oI.I.packedSize(); ++k) oI.I.packed(k) = cb.flat(oI.I.packed(k), "oI");
    V6 h = rigidMul(cb, oI, ov);
    flatten(cb, h, "h");
    V6 f = add(rigidMul(cb, oI, oa), crossForce(cb, ov, h));
    if (withLambda) {
      V6 fc = zero6();
      addConstraintForces(e, i, fc);  // K^T lambda in body coordinates
      f = add(f, actForce(cb, oM, fc));
    }
    const M3 Baa = angularBlockOfB(cb, oI, ov, h);
    W.Ic[b] = keep(e, kWI, i, entriesOf(oI));
    W.HL[b] = keep(e, kWH, i, {h[0], h[1], h[2]});
    W.Baa[b] = keep(e, kWB, i, std::vector<Expr>(Baa.begin(), Baa.end()));
    W.F[b] = keep(e, kWF, i, entries(f));
    cb.close();
  }
}

// Leaves first: body j's columns from its subtree sums, then the sums into its parent.
void backward(Emit& e, World& W) {
  const Plan& plan = e.plan;
  e.fn.beginPass("columns", "backward: the subtree sums Ic, HL, Baa, F and each dof's u, c, w, Pq, Pv, Ic s, Bc^T s");
  for (auto it = plan.sweep.rbegin(); it != plan.sweep.rend(); ++it) {
    const int j = *it;
    const BodyPlan& p = e.bp(j);
    const std::size_t b = std::size_t(j), par = std::size_t(p.parent);
    e.fn.boundary(j);
    e.openBody(j, "world columns");
    CodeBuilder& cb = e.cb();
    const Rigid Ic = rigidFrom(Expr(W.mass[b]), read(cb, W.Ic[b]));
    const V3 HL = read3(cb, W.HL[b]);
    M3 Baa;
    {
      const std::vector<Expr> x = read(cb, W.Baa[b]);
      std::copy(x.begin(), x.end(), Baa.begin());
    }
    const V6 F = read6(cb, W.F[b]), ov = read6(cb, W.ov[b]);
    const V6 ovl = p.parent > 0 ? read6(cb, W.ov[par]) : zero6();
    const V6 oal = p.parent > 0 ? read6(cb, W.oa[par]) : e.rootAcceleration();
    V6 vsum = add(ovl, ov);
    flatten(cb, vsum, "vs");
    for (int d = 0; d < p.nv; ++d) {
      const int k = p.idx_v + d;
      auto& col = W.col[std::size_t(k)];
      const V6 s = read6(cb, col[kS]);
      V6 u = crossMotion(cb, s, ovl);
      flatten(cb, u, "u");
      V6 c = add(neg(crossMotion(cb, s, oal)), crossMotion(cb, u, ovl));
      flatten(cb, c, "c");
      V6 w = neg(crossMotion(cb, s, vsum));
      flatten(cb, w, "w");
      const V6 pq = sub(add(crossForce(cb, s, F), rigidMul(cb, Ic, c)), applyB(cb, HL, Baa, u));
      const V6 pv = add(rigidMul(cb, Ic, w), applyB(cb, HL, Baa, s));
      const V3 hs = cross(cb, HL, lin(s)), bt = rotateT(cb, Baa, ang(s));
      col[kU] = storeColumn(e, kU, k, entries(u));
      col[kC] = storeColumn(e, kC, k, entries(c));
      col[kW] = storeColumn(e, kW, k, entries(w));
      col[kPq] = storeColumn(e, kPq, k, entries(pq));
      col[kPv] = storeColumn(e, kPv, k, entries(pv));
      col[kIS] = storeColumn(e, kIS, k, entries(rigidMul(cb, Ic, s)));
      col[kBS] = storeColumn(e, kBS, k, {2.0 * hs[0] + bt[0], 2.0 * hs[1] + bt[1], 2.0 * hs[2] + bt[2]});
    }
    if (p.parent > 0) {  // into the parent's sums
      W.mass[par] += W.mass[b];
      const std::pair<std::vector<Slots>*, const Quantity*> sums[] = {
          {&W.Ic, &kWI}, {&W.HL, &kWH}, {&W.Baa, &kWB}, {&W.F, &kWF}};
      for (const auto& [x, qy] : sums) {
        const std::vector<Expr> mine = read(cb, (*x)[b]), theirs = read(cb, (*x)[par]);
        std::vector<Expr> total(mine.size());
        for (std::size_t k = 0; k < mine.size(); ++k) total[k] = theirs[k] + mine[k];
        (*x)[par] = keep(e, *qy, p.parent, total);
      }
    }
    cb.close();
  }
}

bool allZero(const Slots& s, std::size_t from, std::size_t to) {
  for (std::size_t r = from; r < to; ++r)
    if (!s[r].name.empty() || !s[r].value.isZero()) return false;
  return true;
}

// The pairs (world_frame_rows and world_frame_columns, assemble.cpp): per dof c
// the rows r whose path holds c (the dofs of c's joint's subtree, its own
// joint's included: c is in r's path exactly when r's joint is c's or below
// it, one range in depth-first order), [rows_v[2c], rows_v[2c + 1]); for
// dtau_dq none for the columns whose c and u's angular part are exact zeros (a
// free flyer's translations: nothing moves the robot's dynamics along them);
// and per dof c the rows of its joint's strict subtree, [below[2c], below[2c + 1]).
void pairs(Emit& e, const World& W, std::set<std::pair<int, int>>& dq, std::set<std::pair<int, int>>& dv) {
  const Plan& plan = e.plan;
  const int nv = plan.nv, N = int(plan.bodies.size());
  std::set<std::pair<int, int>> pathQ, pathV;
  std::vector<int> rowsQ, rowsV, below;
  long subtree = 0, entriesQ = 0, entriesV = 0;
  for (int i = 1; i < N; ++i)
    for (int d = 0; d < e.bp(i).nv; ++d) {
      const int c = e.bp(i).idx_v + d, lo = e.bp(i).idx_v, hi = e.bp(i).dofEnd;
      const auto& col = W.col[std::size_t(c)];
      const bool moves = !allZero(col[kC], 0, 6) || !allZero(col[kU], 3, 6);
      rowsV.insert(rowsV.end(), {lo, hi});
      rowsQ.insert(rowsQ.end(), {moves ? lo : 0, moves ? hi : 0});
      for (int r = lo; r < hi; ++r) {
        pathV.insert({r, c});
        if (moves) pathQ.insert({r, c});
      }
      entriesV += hi - lo;
      entriesQ += moves ? hi - lo : 0;
      below.insert(below.end(), {e.bp(i).idx_v + e.bp(i).nv, e.bp(i).dofEnd});
      subtree += e.bp(i).dofEnd - e.bp(i).idx_v - e.bp(i).nv;
    }
  CodeBuilder& cb = e.cb();
  cb.line(fmt::format("static constexpr int rows_q[{}] = {{{}}};", rowsQ.size(), fmt::join(rowsQ, ", ")));
  cb.line(fmt::format("static constexpr int rows_v[{}] = {{{}}};", rowsV.size(), fmt::join(rowsV, ", ")));
  cb.line(fmt::format("static constexpr int below[{}] = {{{}}};", below.size(), fmt::join(below, ", ")));
  // The loops write exactly the entries of the pattern (rows: the path, own
  // joint included; columns: the strict subtree), and the products of fdd and
  // cdd read no other: only inverse_dynamics_derivatives zeroes the rest, in
  // its caller's outputs (emitter.cpp).
  const auto arr = [](ColumnArray a) { return fmt::format("&w.{}[0][0]", kColumnArrays[a].name); };
  const std::vector<std::string> names = {"w", "dtau_dq", "dtau_dv"};
  OpCount rows;  // per entry a six- and a three-term product, per column s B_c
  rows.once.mul = 9 * entriesQ + 3 * nv;
  rows.once.add = 8 * entriesQ;
  cb.line(fmt::format("world_frame_rows<{}>({}, {}, {}, {}, Scalar(-1), rows_q, dtau_dq);", nv, arr(kIS), arr(kBS),
                      arr(kC), arr(kU)),
          {}, names, rows);
  rows.once.mul = 9 * entriesV + 3 * nv;
  rows.once.add = 8 * entriesV;
  cb.line(fmt::format("world_frame_rows<{}>({}, {}, {}, {}, Scalar(1), rows_v, dtau_dv);", nv, arr(kIS), arr(kBS),
                      arr(kW), arr(kS)),
          {}, names, rows);
  OpCount columns;  // per entry two six-term products
  columns.once.mul = 12 * subtree;
  columns.once.add = 10 * subtree;
  cb.line(fmt::format("world_frame_columns<{}>({}, {}, {}, below, dtau_dq, dtau_dv);", nv, arr(kS), arr(kPq), arr(kPv)),
          {}, names, columns);
  dq = pathQ;
  dv = pathV;
  for (int i = 1; i < N; ++i)
    for (int d = 0; d < e.bp(i).nv; ++d) {
      const int c = e.bp(i).idx_v + d;
      for (int r = e.bp(i).idx_v + e.bp(i).nv; r < e.bp(i).dofEnd; ++r) {
        dq.insert({c, r});
        dv.insert({c, r});
      }
    }
}

}  // namespace

std::vector<TangentSlot> slotsOf(Emit& e, const std::vector<Expr>& x, const std::function<std::string(int)>& member,
                                 bool store) {
  std::vector<TangentSlot> s(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (x[k].isConstant()) {
      s[k].value = x[k];
      continue;
    }
    s[k].name = member(int(k));
    if (store) e.cb().store(s[k].name, x[k]);
  }
  return s;
}

Expr load(CodeBuilder& cb, const TangentSlot& s) { return s.name.empty() ? s.value : cb.member(s.name); }

std::vector<Expr> load(CodeBuilder& cb, const std::vector<TangentSlot>& s) {
  std::vector<Expr> x;
  for (const TangentSlot& t : s) x.push_back(load(cb, t));
  return x;
}

V6 load(CodeBuilder& cb, const TangentCol& s) {
  V6 x;
  for (std::size_t r = 0; r < 6; ++r) x[r] = load(cb, s[r]);
  return x;
}

RowSpans rowSpans(int rows, const std::set<std::pair<int, int>>& entries) {
  RowSpans out(static_cast<std::size_t>(rows));
  for (const auto& [r, c] : entries) {
    auto& spans = out.at(std::size_t(r));
    if (!spans.empty() && spans.back().second == c)
      ++spans.back().second;  // the set is sorted: c extends the last range or opens one
    else
      spans.push_back({c, c + 1});
  }
  return out;
}

void printSpans(CodeBuilder& cb, const std::string& name, const RowSpans& spans) {
  std::vector<int> start{0}, span;
  for (const auto& row : spans) {
    for (const auto& [lo, hi] : row) span.insert(span.end(), {lo, hi});
    start.push_back(int(span.size() / 2));
  }
  if (span.empty()) span = {0, 0};  // no entry: a range nothing reads (no zero-length array)
  cb.line(fmt::format("static constexpr int {}_start[{}] = {{{}}};", name, start.size(), fmt::join(start, ", ")));
  cb.line(fmt::format("static constexpr int {}_span[{}] = {{{}}};", name, span.size(), fmt::join(span, ", ")));
}

std::set<std::pair<int, int>> transpose(const std::set<std::pair<int, int>>& entries) {
  std::set<std::pair<int, int>> out;
  for (const auto& [r, c] : entries) out.insert({c, r});
  return out;
}

long entries(const RowSpans& spans) {
  long nnz = 0;
  for (const auto& row : spans)
    for (const auto& [lo, hi] : row) nnz += hi - lo;
  return nnz;
}

void copyBlock(CodeBuilder& cb, const std::vector<std::string>& names, const std::string& dst, const std::string& src,
               int rows, int cols, int ld, int offset, bool transposed, const CopyTo& to) {
  cb.open(fmt::format("for (int i = 0; i < {}; ++i) {{", rows), {}, names);
  cb.open(fmt::format("for (int j = 0; j < {}; ++j) {{", cols), {}, names);
  const std::string at = offset == 0 ? "" : fmt::format(" + {}", offset);
  const std::string from = transposed ? fmt::format("j * {}{} + i", ld, at) : fmt::format("i * {}{} + j", ld, at);
  const int dstLd = to.ld == 0 ? cols : to.ld;
  const std::string dstAt = to.offset == 0 ? "" : fmt::format(" + {}", to.offset);
  OpCount ops;  // per entry: the loops' trips multiply it
  ops.once.neg = to.negate ? 1 : 0;
  cb.line(fmt::format("{}[i * {}{} + j] = {}{}[{}];", dst, dstLd, dstAt, to.negate ? "-" : "", src, from), {}, names, ops);
  cb.close();
  cb.close();
}

// sparse_left_product_add<n, m, p> and sparse_transposed_product<n, m, p>:
// per entry of the left factor, its scaling and p multiply-adds.
Ops sparseLeftProductOps(const RowSpans& a, int p) {
  const long nnz = entries(a);
  Ops o;
  o.mul = nnz * (p + 1);
  o.add = nnz * p;
  return o;
}

// M^-1 is symmetric, so X = -M^-1 dtau is X^T = -dtau^T M^-1: each row of X^T
// sums full rows of M^-1 over one column of dtau's nonzero entries (the inner
// loop of fixed length, as in the dense product), then X^T is copied out
// transposed.
void minvTimesDtau(Emit& e, const BodyTangents& t, const std::string& minv, const std::string& dq,
                   const std::string& dv, const std::string& scratch, const std::vector<std::string>& names) {
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  const std::pair<const std::set<std::pair<int, int>>*, std::string> products[] = {{&t.dtauDq, "dq"},
                                                                                   {&t.dtauDv, "dv"}};
  for (const auto& [entries, x] : products) {
    const RowSpans spans = rowSpans(nv, transpose(*entries));
    const std::string table = "dtau_" + x + "_t";
    printSpans(cb, table, spans);
    OpCount ops;
    ops.once = sparseLeftProductOps(spans, nv);
    cb.line(fmt::format("sparse_transposed_product<{0}, {0}, {0}>({1}, {2}_start, {2}_span, {3}, Scalar(-1), {4});", nv,
                        x == "dq" ? dq : dv, table, minv, scratch),
            {}, names, ops);
    copyBlock(cb, names, "dqdd_" + x, scratch, nv, nv, nv, 0, true);
  }
}

// The arithmetic of dense_product<n, m, p> (assemble.cpp prints it): per row
// r and k, the scaling s A_rk, then p multiply-adds into C's row.
Ops denseProductOps(int n, int m, int p) {
  Ops o;
  o.mul = long(n) * m * (p + 1);
  o.add = long(n) * m * p;
  return o;
}

std::string emitForwardDynamicsDerivatives(Emit& e, const BodyTangents& t) {
  const Plan& plan = e.plan;
  const int nv = plan.nv;
  if (nv == 0) fail("layout", "functions", "'forward_dynamics_derivatives' is not generated for a robot without joints (nv = 0)");
  const auto array = [&](const std::string& base, int size, const std::string& comment) {
    e.ws.member(base, size, 0, comment);
    return "w." + base;
  };
  const std::string h = array("fdd_h", nv, "h(q, v) (forward_dynamics_derivatives)");
  const std::string dq = array("fdd_dtau_dq", nv * nv, "d tau / dq at (q, v, qdd) (forward_dynamics_derivatives)");
  const std::string dv = array("fdd_dtau_dv", nv * nv, "d tau / dv at (q, v, qdd) (forward_dynamics_derivatives)");
  const std::string xt = array("fdd_Xt", nv * nv, "d qdd / dq or d qdd / dv, transposed (forward_dynamics_derivatives)");
  e.fn.live() = Live{};
  e.fn.beginHost("fdd", nullptr);
  CodeBuilder& cb = e.cb();
  const std::vector<std::string> names = {"q", "v", "tau", "w", "qdd", "dqdd_dq", "dqdd_dv", "dqdd_dtau"};
  OpCount ops;
  cb.line(fmt::format("nonlinear_effects(q, v, w, {});", h), {}, names);
  // nonlinear_effects' kinematics pass wrote the joint transforms of this q.
  cb.line("mass_matrix_inverse_passes(q, w, dqdd_dtau);", {}, names);
  // h := tau - h, then qdd = M^-1 (tau - h): ABA's answer to round-off.
  ops.once = Ops{};
  ops.once.add = nv;
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = tau[k] - {}[k];", nv, h, h), {}, names, ops);
  ops.once = denseProductOps(nv, nv, 1);
  cb.line(fmt::format("dense_product<{0}, {0}, 1>(dqdd_dtau, {1}, Scalar(1), qdd);", nv, h), {}, names, ops);
  // The sweep reads the kinematics state nonlinear_effects left for the same (q, v):
  // neither RNEA nor mass_matrix_inverse writes v, c or pA (no second kinematics pass).
  cb.line(fmt::format("tangent_sweep(q, v, qdd, nullptr, w, {}, {});", dq, dv), {}, names);
  // dqdd_dx = -M^-1 dtau_dx over dtau's nonzero entries (the tree's pattern).
  minvTimesDtau(e, t, "dqdd_dtau", dq, dv, xt, names);
  return e.fn.endHost(names);
}

std::string emitInverseDynamicsDerivatives(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics,
                                           BodyTangents* keepOut) {
  const Plan& plan = e.plan;
  const bool withLambda = plan.nc > 0;
  const int N = int(plan.bodies.size());
  World W;
  for (std::vector<Slots>* x : {&W.oR, &W.op, &W.ov, &W.oa, &W.Ic, &W.HL, &W.Baa, &W.F}) x->assign(std::size_t(N), Slots{});
  W.col.resize(std::size_t(plan.nv));
  W.mass.assign(std::size_t(N), 0.0);
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.beginHost("rnead", afterKinematics);
  CodeBuilder& host = e.cb();
  if (withLambda) {
    // lambda == nullptr: no constraint forces (a pointer select, no branch in the arithmetic).
    host.line(fmt::format("static constexpr Scalar kNoMultipliers[{}] = {{}};", plan.nc));
    host.line("lambda = lambda != nullptr ? lambda : kNoMultipliers;", {}, {"lambda"});
  }
  forward(e, kin, withLambda, W);
  backward(e, W);
  BodyTangents t;
  const auto col6 = [](const Slots& s) {
    TangentCol c;
    std::copy(s.begin(), s.end(), c.begin());
    return c;
  };
  for (const auto& col : W.col)
    t.dof.push_back({col6(col[ColumnArray::kS]), col6(col[ColumnArray::kU]), col6(col[ColumnArray::kC]),
                     col6(col[ColumnArray::kW])});
  t.body.resize(std::size_t(N));
  for (std::size_t b = 1; b < std::size_t(N); ++b) {
    t.body[b].ov = col6(W.ov[b]);
    std::copy(W.oR[b].begin(), W.oR[b].end(), t.body[b].R.begin());
    std::copy(W.op[b].begin(), W.op[b].end(), t.body[b].p.begin());
  }
  e.fn.endPart();
  pairs(e, W, t.dtauDq, t.dtauDv);
  if (keepOut != nullptr) *keepOut = std::move(t);
  std::string text = e.fn.endHost({"q", "v", "qdd", "lambda", "w", "dtau_dq", "dtau_dv"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

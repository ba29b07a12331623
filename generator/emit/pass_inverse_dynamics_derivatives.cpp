// The derivatives of inverse dynamics, tau = RNEA(q, v, qdd) + J^T lambda, at
// fixed qdd and lambda: one forward-mode tangent sweep along every q and v
// direction (docs/derivatives.md section 2), straight-line, with the model's
// zeros folded. Perturbing joint j by dq_j moves its placement to
// X_J Exp(S_j dq_j), so for body i and a column k (an input direction):
//   forward, root first, k among the dofs of i's path from the root:
//     dv_i = X^-1 dv_p  (+ (X^-1 v_p) x S_k for i's own q dofs; = S_k for its own v dofs)
//     da_i = X^-1 da_p + dv_i x vJ  (+ (X^-1 a_p) x S_k, own q dofs; + v_i x S_k, own v dofs)
//     df_i = I da_i + dv_i x* I v_i + v_i x* I dv_i
//   backward, leaves first, k among the path's and the subtree's dofs:
//     dtau_i[k] = S_i^T df_i ;  df_p += X df_i  (+ X (S_k x* f_i), own q dofs),
// f_i the accumulated subtree force with the constraint forces K_c^T lambda_c.
// A column outside a body's path (forward) or path and subtree (backward) is
// zero and never printed. The tangents move between the part functions in
// workspace members (6 x nv per body, only the path's columns written); the
// host copies the nonzero entries out and writes the zeros. A run of adjacent
// columns of one shape is one loop over j instead of a block per column
// (below, "Column loops"; docs/derivatives.md).
// The generic counterpart: algorithms/derivatives.cpp (tangentSweep).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <map>

#include "emit/passes.hpp"
#include "model/error.hpp"

namespace proxgen::emit {
namespace {

constexpr Quantity kDvq{"dvq", "d v / dq (6 x nv, path columns)"}, kDvv{"dvv", "d v / dv (6 x nv, path columns)"},
    kDaq{"daq", "d a / dq at fixed qdd (6 x nv, path columns)"}, kDav{"dav", "d a / dv at fixed qdd (6 x nv, path columns)"},
    kDfq{"dfq", "d f / dq, subtree force (6 x nv)"}, kDfv{"dfv", "d f / dv, subtree force (6 x nv)"};

using Slot = TangentSlot;
using Col = TangentCol;
using Cols = TangentCols;

// Stores x's non-constant entries as column `col` of the body's 6 x nv
// member; in a loop over a run of columns (`loop`), as column col + j.
Col save(Emit& e, const Quantity& qy, int body, int col, const V6& x, bool loop = false) {
  Col s;
  for (int r = 0; r < 6; ++r) {
    const Expr& v = x[std::size_t(r)];
    if (v.isConstant()) {
      s[std::size_t(r)].value = v;
    } else {
      s[std::size_t(r)].name =
          loop ? e.loopSlot(qy, body, 6, e.plan.nv, r, col) : e.member(qy, body, 6, e.plan.nv, r, col);
      e.cb().store(s[std::size_t(r)].name, v);
    }
  }
  return s;
}

// Column loops. The columns of a body's tangents go through the same
// arithmetic with the same coefficients (the body's transform, inertia and
// velocity); only which members they read differs. A run of adjacent columns
// whose inputs have the same shape (each entry a stored member in all of
// them, or the same constant in all) is one loop over j, the members indexed
// [c0 + j], instead of a copy of the code per column: the sweep's code shrinks
// by the depth of the tree, and the compiler vectorises the loop across
// columns (columnRuns and openColumns: column_loops.cpp; docs/derivatives.md,
// "Column loops").

bool sameShape(const Col& a, const Col& b) {
  for (std::size_t r = 0; r < 6; ++r) {
    if (a[r].name.empty() != b[r].name.empty()) return false;
    if (a[r].name.empty() && a[r].value.constant() != b[r].value.constant()) return false;
  }
  return true;
}

// `c`'s stored entries read as the loop's column c0 + j (c: column c0's slots).
Col loopColumn(Emit& e, const Quantity& qy, int body, const Col& c, int c0) {
  Col out = c;
  for (int r = 0; r < 6; ++r)
    if (!c[std::size_t(r)].name.empty()) out[std::size_t(r)].name = e.loopSlot(qy, body, 6, e.plan.nv, r, c0);
  return out;
}

// After the loop: column k's slots, with the shape the loop gave them; the
// members the loop wrote under its own names are new values from here on.
Col columnAfterLoop(Emit& e, const Quantity& qy, int body, const Col& looped, int k) {
  Col out = looped;
  for (int r = 0; r < 6; ++r)
    if (!looped[std::size_t(r)].name.empty()) {
      out[std::size_t(r)].name = e.member(qy, body, 6, e.plan.nv, r, k);
      e.cb().refresh(out[std::size_t(r)].name);
    }
  return out;
}

std::string vIn(int k) { return fmt::format("v[{}]", k); }
std::string qddIn(int k) { return fmt::format("qdd[{}]", k); }

struct Sweep {
  std::vector<Cols> dvq, dvv, daq, dav, dfq, dfv;  // per body
};

// vJ = S v_i (inputs: valid in every part).
V6 jointVelocity(Emit& e, const Kinematics::Body& kb, const BodyPlan& p) {
  CodeBuilder& cb = e.cb();
  V6 vJ = zero6();
  for (int d = 0; d < p.nv; ++d) {
    const V6 t = scale(cb, cb.input(vIn(p.idx_v + d)), kb.S[std::size_t(d)]);
    vJ = add(vJ, t);
  }
  return vJ;
}

// The velocity terms of the force tangent, dv x* I v + v x* I dv, are linear in
// dv: B dv with B = H(I v) + (v x*) I (H(h) u = u x* h). Its columns B e_k are
// the body's, formed once in its own block from I v and v with I's constants
// (no products), so each column's tangent costs one product per nonzero entry
// of B instead of two cross products and I dv.
std::array<V6, 6> velocityMap(CodeBuilder& cb, const Kinematics::Body& kb, const V6& Iv) {
  std::array<V6, 6> B;
  for (std::size_t k = 0; k < 6; ++k) {
    V6 ek = zero6();
    ek[k] = Expr(1.0);
    B[k] = add(crossForce(cb, ek, Iv), crossForce(cb, kb.v, mul(cb, kb.IA, ek)));
  }
  return B;
}

// df = I da + B dv (I constant: I da needs no products; B: velocityMap).
V6 forceTangent(Emit& e, const Kinematics::Body& kb, const std::array<V6, 6>& B, const V6& da, const V6& dv) {
  CodeBuilder& cb = e.cb();
  V6 df = mul(cb, kb.IA, da);
  for (std::size_t k = 0; k < 6; ++k)
    if (!dv[k].isZero()) df = add(df, scale(cb, dv[k], B[k]));
  return df;
}

// The forward tangents of one column k of body i, given its q and v motion
// tangents before the velocity-product term; stores what the children and the
// backward sweep read.
void finishColumn(Emit& e, const Kinematics::Body& kb, const std::array<V6, 6>& B, int i, int k, const V6& vJ, const V6& dvq,
                  const V6& dvv, const V6& daq0, const V6& dav0, bool store, Sweep& s, bool loop = false) {
  CodeBuilder& cb = e.cb();
  V6 dq = dvq, dv = dvv;
  flatten(cb, dq, "dv");
  flatten(cb, dv, "dv");
  const V6 cq = crossMotion(cb, dq, vJ);
  const V6 cv = crossMotion(cb, dv, vJ);
  V6 daq = add(daq0, cq), dav = add(dav0, cv);
  flatten(cb, daq, "da");
  flatten(cb, dav, "da");
  const std::size_t b = std::size_t(i);
  if (store) {
    s.dvq[b][k] = save(e, kDvq, i, k, dq, loop);
    s.dvv[b][k] = save(e, kDvv, i, k, dv, loop);
    s.daq[b][k] = save(e, kDaq, i, k, daq, loop);
    s.dav[b][k] = save(e, kDav, i, k, dav, loop);
  }
  const V6 fq = forceTangent(e, kb, B, daq, dq);
  s.dfq[b][k] = save(e, kDfq, i, k, fq, loop);
  const V6 fv = forceTangent(e, kb, B, dav, dv);
  s.dfv[b][k] = save(e, kDfv, i, k, fv, loop);
}

void forward(Emit& e, const Kinematics& kin, bool withLambda, bool keepConstrained, Forces& fs, Sweep& s) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size());
  e.fn.beginPass("forward", "forward: a, f, and their tangents along the path's q and v directions");
  for (int i = 1; i < N; ++i) {
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    // The motion tangents are read by the children, and with keepConstrained by
    // constrained_dynamics_derivatives' constraint rows.
    const bool store = !p.children.empty() || (keepConstrained && !p.constraints.empty());
    // The primal RNEA values and the body's own columns.
    e.fn.boundary(i);
    e.openBody(i, "forward");
    {
      CodeBuilder& cb = e.cb();
      V6 ap = p.parent == 0 ? e.rootAcceleration() : fs.a[std::size_t(p.parent)];
      ap = e.motionToChild(kb, ap);
      flatten(cb, ap, "ap");
      V6 a = add(ap, kb.c);
      for (int d = 0; d < p.nv; ++d) {
        const V6 t = scale(cb, cb.input(qddIn(p.idx_v + d)), kb.S[std::size_t(d)]);
        a = add(a, t);
      }
      flatten(cb, a, "a");
      if (store)
        for (int k = 0; k < 6; ++k) fs.a[std::size_t(i)][std::size_t(k)] = e.putQ(kA, i, 6, k, a[std::size_t(k)]);
      const V6 Ia = mul(cb, kb.IA, a);
      V6 f = add(Ia, kb.pA);
      if (withLambda) addConstraintForces(e, i, f);
      for (int k = 0; k < 6; ++k) fs.f[std::size_t(i)][std::size_t(k)] = e.putQ(kF, i, 6, k, f[std::size_t(k)]);
      // B once per body: every column's force tangent reads it, and the
      // carried columns are parts of their own (stored if it has any).
      V6 Iv = mul(cb, kb.IA, kb.v);
      flatten(cb, Iv, "h");
      std::array<V6, 6> B = velocityMap(cb, kb, Iv);
      const bool carried = p.parent > 0 && !s.dvq[std::size_t(p.parent)].empty();
      for (std::size_t c = 0; c < 6; ++c)
        for (std::size_t r = 0; r < 6; ++r) {
          Expr& x = B[c][r];
          if (x.isConstant()) continue;
          if (carried)
            x = e.putQ(kBv, i, 36, int(6 * c + r), x);
          else
            x = cb.flat(x, "b");
        }
      fs.Bv[std::size_t(i)] = B;
      const V6 vJ = jointVelocity(e, kb, p);
      const V6 vp = sub(kb.v, vJ);  // X^-1 v_p
      for (int d = 0; d < p.nv; ++d) {
        const V6& Sk = kb.S[std::size_t(d)];
        const V6 dvq = crossMotion(cb, vp, Sk);
        const V6 daq = crossMotion(cb, ap, Sk);
        const V6 dav = crossMotion(cb, kb.v, Sk);
        finishColumn(e, kb, fs.Bv[std::size_t(i)], i, p.idx_v + d, vJ, dvq, Sk, daq, dav, store, s);
      }
    }
    e.cb().close();
    // The ancestors' columns, carried from the parent: a loop per run of
    // columns of one shape, a block per column elsewhere.
    if (p.parent <= 0) continue;
    const std::size_t par = std::size_t(p.parent);
    std::vector<int> carried;
    for (const auto& kv : s.dvq[par]) carried.push_back(kv.first);
    const auto shapeOf = [&](int k, int k0) {
      return sameShape(s.dvq[par].at(k), s.dvq[par].at(k0)) &&
             sameShape(s.dvv[par].at(k), s.dvv[par].at(k0)) && sameShape(s.daq[par].at(k), s.daq[par].at(k0)) &&
             sameShape(s.dav[par].at(k), s.dav[par].at(k0));
    };
    for (const auto& run : columnRuns(carried, shapeOf)) {
      const int k0 = run.first, len = run.second;  // named: the lambdas below capture them
      const bool loop = len > 1;
      openColumns(e, p.ident, k0, len, fmt::format("body {} '{}',", i, p.ident));
      const auto in = [&](const Quantity& qy, const Cols& c) {
        return loop ? loopColumn(e, qy, p.parent, c.at(k0), k0) : c.at(k0);
      };
      const V6 vJ = jointVelocity(e, kb, p);
      const V6 pq = load(e.cb(), in(kDvq, s.dvq[par]));
      const V6 dvq = e.motionToChild(kb, pq);
      const V6 pv = load(e.cb(), in(kDvv, s.dvv[par]));
      const V6 dvv = e.motionToChild(kb, pv);
      const V6 paq = load(e.cb(), in(kDaq, s.daq[par]));
      const V6 daq = e.motionToChild(kb, paq);
      const V6 pav = load(e.cb(), in(kDav, s.dav[par]));
      const V6 dav = e.motionToChild(kb, pav);
      finishColumn(e, kb, fs.Bv[std::size_t(i)], i, k0, vJ, dvq, dvv, daq, dav, store, s, loop);
      e.cb().close();
      if (loop) {
        const std::size_t b = std::size_t(i);
        const std::pair<const Quantity*, std::vector<Cols>*> stored[] = {
            {&kDvq, &s.dvq}, {&kDvv, &s.dvv}, {&kDaq, &s.daq}, {&kDav, &s.dav}, {&kDfq, &s.dfq}, {&kDfv, &s.dfv}};
        for (const auto& [qy, cols] : stored) {
          Cols& c = (*cols)[b];
          if (c.count(k0) == 0) continue;  // not stored (a leaf's motion tangents)
          const Col looped = c.at(k0);
          for (int k = k0; k < k0 + len; ++k) c[k] = columnAfterLoop(e, *qy, i, looped, k);
        }
      }
    }
  }
}

struct Outputs {
  std::map<std::pair<int, int>, Slot> dq, dv;  // (row, column) -> entry
};

void backward(Emit& e, const Kinematics& kin, Forces& fs, Sweep& s, Outputs& out) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size()), nv = plan.nv;
  e.fn.beginPass("backward", "backward: dtau = S^T df, df_parent += X df (+ X (S_k x* f) along the joint's own q)");
  for (int i = N - 1; i >= 1; --i) {
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    const std::size_t b = std::size_t(i), par = std::size_t(std::max(p.parent, 0));
    for (int pass = 0; pass < 2; ++pass) {
      Cols& cols = pass == 0 ? s.dfq[b] : s.dfv[b];
      const Quantity& qy = pass == 0 ? kDfq : kDfv;
      Cols& pc = pass == 0 ? s.dfq[par] : s.dfv[par];
      const char* dtau = pass == 0 ? "dtau_dq" : "dtau_dv";
      const auto own = [&](int k) { return pass == 0 && k >= p.idx_v && k < p.idx_v + p.nv; };  // + X (S_k x* f)
      // A run: adjacent columns of one shape, none of the joint's own q
      // columns, each met or not met before in the parent, in one shape.
      const auto runs = [&](int k, int k0) {
        if (own(k) || own(k0) || !sameShape(cols.at(k), cols.at(k0))) return false;
        if (p.parent <= 0) return true;
        const auto a = pc.find(k), a0 = pc.find(k0);
        if ((a == pc.end()) != (a0 == pc.end())) return false;
        return a == pc.end() || sameShape(a->second, a0->second);
      };
      std::vector<int> ks;
      for (const auto& kv : cols) ks.push_back(kv.first);
      for (const auto& run : columnRuns(ks, runs)) {
        const int k0 = run.first, len = run.second;
        const bool loop = len > 1;
        openColumns(e, p.ident, k0, len, fmt::format("body {} '{}', {}", i, p.ident, pass == 0 ? "q" : "v"));
        CodeBuilder& cb = e.cb();
        V6 df = load(cb, loop ? loopColumn(e, qy, i, cols.at(k0), k0) : cols.at(k0));
        std::vector<Slot> rows(std::size_t(p.nv));
        for (int d = 0; d < p.nv; ++d) {
          const int row = p.idx_v + d;
          const Expr t = dot(cb, kb.S[std::size_t(d)], df);
          Slot& slot = rows[std::size_t(d)];
          if (t.isConstant()) {
            slot.value = t;
          } else {
            const std::string what = "d tau / dq or d tau / dv (row-major)";
            slot.name = loop ? e.ws.loopSlot(dtau, nv, nv, row, k0, what) : e.ws.member(dtau, nv, nv, row, k0, what);
            cb.store(slot.name, t);
          }
        }
        Col parentCol;
        bool toParent = false;
        if (p.parent > 0) {
          if (own(k0)) {
            const V6 carried = crossForce(cb, kb.S[std::size_t(k0 - p.idx_v)], fs.f[b]);
            df = add(df, carried);
          }
          const V6 dp = e.forceToParent(kb, df);
          V6 sum = dp;
          if (const auto it = pc.find(k0); it != pc.end()) {
            const V6 old = load(cb, loop ? loopColumn(e, qy, p.parent, it->second, k0) : it->second);
            sum = add(old, dp);
          }
          parentCol = save(e, qy, p.parent, k0, sum, loop);
          toParent = true;
        }
        cb.close();
        for (int k = k0; k < k0 + len; ++k) {
          for (int d = 0; d < p.nv; ++d) {
            Slot slot = rows[std::size_t(d)];
            if (loop && !slot.name.empty()) {
              slot.name = e.ws.member(dtau, nv, nv, p.idx_v + d, k, "d tau / dq or d tau / dv (row-major)");
              cb.refresh(slot.name);
            }
            (pass == 0 ? out.dq : out.dv)[{p.idx_v + d, k}] = slot;
          }
          if (toParent) pc[k] = loop ? columnAfterLoop(e, qy, p.parent, parentCol, k) : parentCol;
        }
      }
    }
    if (p.parent > 0) {
      e.fn.boundary(i);
      e.openBody(i, "backward");
      const V6 dp = e.forceToParent(kb, fs.f[b]);
      V6& pf = fs.f[par];
      for (int k = 0; k < 6; ++k)
        if (!dp[std::size_t(k)].isZero()) pf[std::size_t(k)] = e.putQ(kF, p.parent, 6, k, pf[std::size_t(k)] + dp[std::size_t(k)]);
      e.cb().close();
    }
  }
}

// out[r * nv + c] for every entry: zeros by a loop, then the nonzero ones;
// returns the nonzero entries.
std::set<std::pair<int, int>> copyOut(Emit& e, const std::map<std::pair<int, int>, Slot>& entries, const char* out) {
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = Scalar(0);", nv * nv, out), {}, {out});
  std::set<std::pair<int, int>> nonzero;
  for (const auto& [rc, slot] : entries) {
    const Expr x = slot.name.empty() ? slot.value : cb.member(slot.name);
    if (x.isZero()) continue;
    cb.line(fmt::format("{}[{}] = {};", out, rc.first * nv + rc.second, cb.print(x)), {x}, {out});
    nonzero.insert(rc);
  }
  return nonzero;
}

}  // namespace

V6 load(CodeBuilder& cb, const TangentCol& s) {
  V6 x;
  for (std::size_t r = 0; r < 6; ++r) x[r] = s[r].name.empty() ? s[r].value : cb.member(s[r].name);
  return x;
}

std::string emitInverseDynamicsDerivatives(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics,
                                           BodyTangents* keep, bool keepConstrained) {
  const Plan& plan = e.plan;
  const bool withLambda = plan.nc > 0;
  const int N = int(plan.bodies.size());
  Forces forces{std::vector<V6>(std::size_t(N), zero6()), std::vector<V6>(std::size_t(N), zero6()),
                std::vector<Expr>(std::size_t(plan.nv)), std::vector<std::array<V6, 6>>(std::size_t(N))};
  Sweep s;
  for (std::vector<Cols>* t : {&s.dvq, &s.dvv, &s.daq, &s.dav, &s.dfq, &s.dfv}) t->assign(std::size_t(N), Cols{});
  Outputs out;
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().forces = &forces;
  e.fn.beginHost("rnead", afterKinematics);
  CodeBuilder& host = e.cb();
  if (withLambda) {
    // lambda == nullptr: no constraint forces (a pointer select, no branch in the arithmetic).
    host.line(fmt::format("static constexpr Scalar kNoMultipliers[{}] = {{}};", plan.nc));
    host.line("lambda = lambda != nullptr ? lambda : kNoMultipliers;", {}, {"lambda"});
  }
  forward(e, kin, withLambda, keepConstrained, forces, s);
  if (keep != nullptr) *keep = BodyTangents{s.dvq, s.dvv, s.daq, s.dav, {}, {}};
  backward(e, kin, forces, s, out);
  e.fn.endPart();
  std::set<std::pair<int, int>> dq = copyOut(e, out.dq, "dtau_dq");
  std::set<std::pair<int, int>> dv = copyOut(e, out.dv, "dtau_dv");
  if (keep != nullptr) {
    keep->dtauDq = std::move(dq);
    keep->dtauDv = std::move(dv);
  }
  std::string text = e.fn.endHost({"v", "qdd", "lambda", "w", "dtau_dq", "dtau_dv"});
  e.fn.live() = Live{};
  return text;
}

std::string emitBiasForces(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics) {
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.beginHost("bias", afterKinematics);
  e.fn.beginPass("", "pA = v x* I v of the bodies with children (the elimination's articulated bias in their members)");
  for (int i = 1; i < int(e.plan.bodies.size()); ++i) {
    if (e.bp(i).children.empty()) continue;  // a leaf's member still holds its own pA
    e.fn.boundary(i);
    e.openBody(i, "bias");
    storeBiasForce(e, i, kin.b[std::size_t(i)]);
    e.cb().close();
  }
  std::string text = e.fn.endHost({"v", "w"});  // v: a velocity equal to an input is read from it
  e.fn.live() = Live{};
  return text;
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
  cb.line(fmt::format("tangent_sweep(v, qdd, nullptr, w, {}, {});", dq, dv), {}, names);
  // dqdd_dx = -M^-1 dtau_dx over dtau's nonzero entries (the tree's pattern).
  minvTimesDtau(e, t, "dqdd_dtau", dq, dv, xt, names);
  return e.fn.endHost(names);
}

}  // namespace proxgen::emit

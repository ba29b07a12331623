// The joint-space inertia M(q) by the composite-rigid-body algorithm, leaves
// first: F = Ic_i S_i, M_ii = S_i^T F, then F carried to each ancestor j
// (F = X^T F) gives M_ji = S_j^T F; Ic_p += X_i^T Ic_i X_i, the composite
// inertias by their ten parameters (symbolic.hpp, Rigid). The carrying goes
// ancestor by ancestor (every column of a subtree one step up at its root's
// turn), so a body's descendants' columns are one loop, through up to three
// bodies where a parent has a single child. A leaf's Ic is its
// own inertia, a constant, so its diagonal entry folds. Each entry is written
// once, where it is computed, into both halves of the output M (no workspace
// copy); the zeros between branches by one fill before the pass, the other
// constant ones after it. Also the q-only joint
// transforms (joint_transforms(q, w)) that the joint-space functions without a
// velocity start from. The generic counterpart: algorithms/crba.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <vector>

#include "emit/passes.hpp"

namespace proxgen::emit {

Kinematics emitJointTransforms(Emit& e) {
  const Model& m = e.model();
  Kinematics kin;
  kin.b.resize(std::size_t(m.numBodies()));
  const InScope<Kinematics> scope(e.fn.live().kin, &kin);
  sincosRuns(e);
  for (int i = 1; i < m.numBodies(); ++i) {
    e.fn.boundary(i);
    e.openBody(i, "");
    Kinematics::Body& b = kin.b[std::size_t(i)];
    jointTransform(e, i, b);
    b.IA = constant(m.bodies[std::size_t(i)].inertia.matrix());
    e.cb().close();
  }
  return kin;
}

namespace {

// M_rc (r <= c) straight into the output, both triangles from the one value:
// a copy through the workspace after the pass was a load and two stores per
// entry, and a third of the function's code. Constant entries (zeros between
// branches, the base's mass) stay in js.upper for finishMassMatrix.
void putMass(Emit& e, JointSpace& js, std::vector<char>& written, int r, int c, const Expr& value) {
  const int nv = e.plan.nv;
  if (value.isConstant()) {
    js.upper(r, c) = value;
    return;
  }
  CodeBuilder& cb = e.cb();
  const Expr t = cb.flat(value, "m");
  cb.line(fmt::format("M[{}] = {};", r * nv + c, cb.print(t)), {t}, {"M"});
  if (r != c) cb.line(fmt::format("M[{}] = {};", c * nv + r, cb.print(t)), {t}, {"M"});
  written[std::size_t(Sym::index(nv, r, c))] = 1;
}

// Whether the host zeroes all of M in one fill before the pass rather than
// the runs of zeros after it. The zeros are the entries of two dofs on
// different branches (neither body an ancestor of the other): 70 % of a
// humanoid's M. GCC writes a loop over 16 or more of them as an inlined
// `rep stosq`, whose start-up (some 25 cycles) dominates a run of a row's
// length; the fill is one start-up and nv^2 8 bytes at some 32 bytes a cycle.
// Talos: 94 runs, 0.77 of 3.1 us, against 0.1 us for the fill (the time
// 0.78 of before); Solo's runs are short (stores, no `rep`) and a fill was
// 1.06 of their time (docs/benchmarks.md).
bool fillFirst(Emit& e) {
  const int nv = e.plan.nv;
  std::vector<int> body(std::size_t(nv), 0);
  for (int i = 1; i < int(e.plan.bodies.size()); ++i)
    for (int d = 0; d < e.bp(i).nv; ++d) body[std::size_t(e.bp(i).idx_v + d)] = i;
  auto zero = [&](int k) {
    const int lo = std::min(k / nv, k % nv), hi = std::max(k / nv, k % nv);
    return hi >= e.bp(body[std::size_t(lo)]).dofEnd;
  };
  int longRuns = 0;
  for (int k = 0; k < nv * nv;) {
    int run = 0;
    while (k < nv * nv && zero(k)) ++run, ++k;
    if (run >= 16) ++longRuns;
    if (run == 0) ++k;
  }
  return 25 * longRuns > 25 + nv * nv / 4;
}

// The entries the pass left constant and the fill did not set: a leaf's own
// inertia, the base's mass, and without a fill the zeros, runs of them as loops.
void finishMassMatrix(Emit& e, const JointSpace& js, const std::vector<char>& written, bool filled) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  auto value = [&](int k) { return js.upper(std::min(k / nv, k % nv), std::max(k / nv, k % nv)); };
  auto pending = [&](int k) {
    return !written[std::size_t(Sym::index(nv, std::min(k / nv, k % nv), std::max(k / nv, k % nv)))] &&
           !(filled && value(k).isZero());
  };
  for (int k = 0; k < nv * nv;) {
    if (!pending(k)) {
      ++k;
      continue;
    }
    const Expr x = value(k);
    int end = k + 1;
    if (x.isZero())
      while (end < nv * nv && pending(end) && value(end).isZero()) ++end;
    if (end - k > 2)
      cb.line(fmt::format("for (int k = {}; k < {}; ++k) M[k] = {};", k, end, cb.print(x)), {}, {"M"});
    else
      for (int j = k; j < end; ++j) cb.line(fmt::format("M[{}] = {};", j, cb.print(x)), {}, {"M"});
    k = end;
  }
}

// The CRBA columns carried up the tree (column k: the composite force of a unit
// acceleration of dof k, F = X^T ... Ic_k S_k), in one 6 x nv member, each
// column in the frame of the body whose turn it is; carrying a column to the
// parent overwrites it in place.
std::string columnSlot(Emit& e, int r, int k, bool loop) {
  const char* what = "CRBA columns, each in the frame of the body being visited";
  return loop ? e.ws.loopSlot("Fcol", 6, e.plan.nv, r, k, what) : e.ws.member("Fcol", 6, e.plan.nv, r, k, what);
}

// M(row, k + j) for the j of a loop over columns k..k + len - 1, into both
// triangles; a constant is the same in every column of the run (one shape).
void putMassColumns(Emit& e, JointSpace& js, std::vector<char>& written, int row, int k0, int len, const Expr& value) {
  if (len == 1 || value.isConstant()) {
    for (int k = k0; k < k0 + len; ++k) putMass(e, js, written, row, k, value);
    return;
  }
  const int nv = e.plan.nv;
  CodeBuilder& cb = e.cb();
  const Expr t = cb.flat(value, "m");
  cb.line(fmt::format("M[{} + j] = {};", row * nv + k0, cb.print(t)), {t}, {"M"});
  cb.line(fmt::format("M[{} + {} * j] = {};", k0 * nv + row, nv, cb.print(t)), {t}, {"M"});
  for (int k = k0; k < k0 + len; ++k) written[std::size_t(Sym::index(nv, row, k))] = 1;
}

// Column k0 (or, in a loop, columns k0 + j) of body i's subtree, F in i's frame:
// F = X_i^T F into the parent's frame, M(parent's dofs, k) = S_p^T F, and F
// kept in its slot for the grandparent. In place: an entry the transform
// leaves as it was is not stored again (a rotation about x can keep two of
// the six), and one that is a multiple of another entry or a product with one (X
// permutes and scales them; flatten leaves those as they are) is read into a
// temporary before any store can overwrite that entry.
struct Carried {
  V6 value = zero6();            // the slots' values after the step (zero when not kept)
  std::array<bool, 6> stored{};  // entries written by this step
};

// One step of a column: G = X_b^T F into the frame of b's parent, whose dofs
// read their entries M(parent's dofs, k) = S^T G.
V6 stepColumn(Emit& e, const Kinematics& kin, int b, int k0, int len, const V6& F, JointSpace& js,
              std::vector<char>& written) {
  CodeBuilder& cb = e.cb();
  const BodyPlan& pp = e.bp(e.bp(b).parent);
  V6 G = e.forceToParent(kin.b[std::size_t(b)], F);
  flatten(cb, G, "F");
  const Kinematics::Body& kp = kin.b[std::size_t(e.bp(b).parent)];
  for (int r = 0; r < pp.nv; ++r)  // an ancestor's dofs come first: the upper triangle
    putMassColumns(e, js, written, pp.idx_v + r, k0, len, dot(cb, kp.S[std::size_t(r)], G));
  return G;
}

// The column, in the frame of b's parent after the step through b, kept in
// its slot for the grandparent, unless b's parent is a child of the world
// (then nothing reads it again).
Carried keepColumn(Emit& e, int b, int k0, int len, V6 G) {
  CodeBuilder& cb = e.cb();
  Carried out;
  if (e.bp(e.bp(b).parent).parent == 0) return out;
  const bool loop = len > 1;
  std::array<bool, 6> unchanged{};
  for (int r = 0; r < 6; ++r) {
    Expr& g = G[std::size_t(r)];
    unchanged[std::size_t(r)] = !g.isConstant() && cb.describe(g) == columnSlot(e, r, k0, loop);
    if (!unchanged[std::size_t(r)] && g.isScaledAtom()) g = cb.snapshot(g, "F");
  }
  for (int r = 0; r < 6; ++r) {
    const std::size_t u = std::size_t(r);
    out.stored[u] = !unchanged[u] && !G[u].isConstant();
    out.value[u] = out.stored[u] ? cb.store(columnSlot(e, r, k0, loop), G[u]) : G[u];
  }
  return out;
}

Carried carryColumn(Emit& e, const Kinematics& kin, int i, int k0, int len, const V6& F, JointSpace& js,
                    std::vector<char>& written) {
  return keepColumn(e, i, k0, len, stepColumn(e, kin, i, k0, len, F, js, written));
}

// Columns go up a chain of single children in one loop: at a body whose
// parent has no other child, its descendants' columns wait, and at the
// parent's turn they go through both transforms with no store of Fcol
// between them. At most this many bodies per loop: a chain body's own column
// joins the walk later than the columns below it and goes through its steps
// alone, so longer loops cost more single columns than they save. Measured
// (docs/benchmarks.md, "CRBA's columns up single-child chains"): 2, 3, 4 and
// 6 on Talos and the Atlas; 3 was the fastest.
constexpr int kChainSteps = 3;

// Ic_p += the child's composite inertia dI, already in p's frame: the mass
// folds; h and I, those of the 9 entries that vary, in member Ic_p (h, then
// I's upper triangle by rows).
void addToParent(Emit& e, int parent, const Rigid& dI, Rigid& par) {
  par.m = par.m + dI.m;
  for (int k = 0; k < 3; ++k) {
    Expr& x = par.h[std::size_t(k)];
    if (!dI.h[std::size_t(k)].isZero()) x = e.putQ(kIc, parent, 9, k, x + dI.h[std::size_t(k)]);
  }
  for (int k = 0; k < 6; ++k)
    if (!dI.I.packed(k).isZero()) par.I.packed(k) = e.putQ(kIc, parent, 9, 3 + k, par.I.packed(k) + dI.I.packed(k));
}

// Fills js (in the caller's Live). Body i, leaves first: its own columns F =
// Ic_i S_i (M_ii = S_i^T F), Ic_p += X^T Ic_i X; then every column of its
// subtree goes up to the parent's frame, where the parent's dofs read their
// entries: one step, or, for columns that waited below i (kChainSteps), the
// steps from the body whose frame they are in. A body's descendants' columns
// all go through the same transforms, so runs of them of one shape are one
// loop (column_loops.cpp): the walk is O(n) code instead of O(n depth).
void compositeInertias(Emit& e, const Kinematics& kin, JointSpace& js, std::vector<char>& written) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size()), nv = plan.nv;
  std::vector<V6>& cols = js.carried;
  cols.assign(std::size_t(nv), zero6());
  std::vector<int> frameOf(std::size_t(nv), 0);  // the body in whose frame column k is
  e.fn.beginPass("", "composite inertias, leaves first: M_ji = S_j^T X^T ... Ic_i S_i");
  for (int i = N - 1; i >= 1; --i) {
    e.fn.boundary(i);
    e.openBody(i, "composite");
    CodeBuilder& cb = e.cb();
    const BodyPlan& p = e.bp(i);
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    std::vector<V6> F(std::size_t(p.nv));
    for (int d = 0; d < p.nv; ++d) {
      F[std::size_t(d)] = mul(cb, spatial(js.Ic[std::size_t(i)]), kb.S[std::size_t(d)]);
      flatten(cb, F[std::size_t(d)], "F");
    }
    for (int r = 0; r < p.nv; ++r)
      for (int c = r; c < p.nv; ++c)
        putMass(e, js, written, p.idx_v + r, p.idx_v + c, dot(cb, kb.S[std::size_t(r)], F[std::size_t(c)]));
    if (p.parent > 0) {
      for (int d = 0; d < p.nv; ++d) {
        cols[std::size_t(p.idx_v + d)] = carryColumn(e, kin, i, p.idx_v + d, 1, F[std::size_t(d)], js, written).value;
        frameOf[std::size_t(p.idx_v + d)] = p.parent;
      }
      addToParent(e, p.parent, e.inertiaToParent(kb, js.Ic[std::size_t(i)]), js.Ic[std::size_t(p.parent)]);
    }
    cb.close();
    if (p.parent == 0) continue;
    // The descendants' columns, each in the frame of the body frameOf[k]
    // (i, or below i where they waited: kChainSteps), up to i's parent.
    std::vector<int> ks;
    for (int k = p.idx_v + p.nv; k < p.dofEnd; ++k) ks.push_back(k);
    auto steps = [&](int k) {  // the bodies from frameOf[k] up to i
      std::vector<int> path;
      for (int b = frameOf[std::size_t(k)]; b != p.parent; b = e.bp(b).parent) path.push_back(b);
      return path;
    };
    const int par = p.parent;
    int longest = 0;
    for (int k : ks) longest = std::max(longest, int(steps(k).size()));
    if (!ks.empty() && e.bp(par).children.size() == 1 && e.bp(par).parent > 0 && longest < kChainSteps)
      continue;  // they go on with the parent's own step
    const auto inputs = [&](int k) { return entries(cols[std::size_t(k)]); };
    const auto sameShape = [&](int k, int k0) {
      return frameOf[std::size_t(k)] == frameOf[std::size_t(k0)] && oneShape(e.cb(), inputs, k, k0);
    };
    for (const auto& run : columnRuns(ks, sameShape)) {
      const int k0 = run.first, len = run.second;
      const std::vector<int> path = steps(k0);
      const std::string label =
          path.size() == 1
              ? fmt::format("body {} '{}', subtree columns to the parent,", i, p.ident)
              : fmt::format("bodies {} to {} ('{}' to '{}'), subtree columns to the parent,", path.front(), i,
                            e.bp(path.front()).ident, p.ident);
      openColumns(e, p.ident, k0, len, label);
      CodeBuilder& lb = e.cb();  // after openColumns: it may have started a new part
      V6 G = len > 1 ? toV6(loopReads(lb, inputs(k0))) : cols[std::size_t(k0)];
      for (int b : path) G = stepColumn(e, kin, b, k0, len, G, js, written);
      const Carried out = keepColumn(e, i, k0, len, G);
      lb.close();
      for (int k = k0; k < k0 + len; ++k) frameOf[std::size_t(k)] = par;
      if (len == 1) {
        cols[std::size_t(k0)] = out.value;
        continue;
      }
      // After a loop the slots it wrote hold new values: read them by their own
      // names; the others hold what they held (or the constant they all share).
      for (int k = k0; k < k0 + len; ++k)
        for (int r = 0; r < 6; ++r) {
          Expr& c = cols[std::size_t(k)][std::size_t(r)];
          if (out.stored[std::size_t(r)]) c = lb.refresh(columnSlot(e, r, k, false));
          else if (out.value[std::size_t(r)].isConstant()) c = out.value[std::size_t(r)];
        }
    }
  }
}

}  // namespace

std::string emitMassMatrix(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms) {
  JointSpace js;
  js.upper = Sym(e.plan.nv);
  for (const Kinematics::Body& b : kin.b) js.Ic.push_back(rigidOf(b.IA));
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().js = &js;
  e.fn.beginHost("crba", afterTransforms);
  const bool fill = fillFirst(e);
  if (fill)
    e.cb().line(fmt::format("for (int k = 0; k < {}; ++k) M[k] = Scalar(0);", e.plan.nv * e.plan.nv), {}, {"M"});
  e.cb().line("joint_transforms(q, w);", {}, {"q", "w"});
  std::vector<char> written(std::size_t(e.plan.nv * (e.plan.nv + 1) / 2), 0);
  compositeInertias(e, kin, js, written);
  finishMassMatrix(e, js, written, fill);
  std::string text = e.fn.endHost({"q", "w", "M"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

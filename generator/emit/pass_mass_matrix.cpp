// The joint-space inertia M(q) by the composite-rigid-body algorithm, leaves
// first: F = Ic_i S_i, M_ii = S_i^T F, then F carried to each ancestor j
// (F = X^T F) gives M_ji = S_j^T F; Ic_p += X_i^T Ic_i X_i. A leaf's Ic is its
// own inertia, a constant, so its diagonal entry folds. Each entry is written
// once, where it is computed, into both halves of the output M (no workspace
// copy); the constant ones after the pass. Also the q-only joint
// transforms (joint_transforms(q, w)) that the joint-space functions without a
// velocity start from. The generic counterpart: algorithms/crba.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "emit/passes.hpp"

namespace proxgen::emit {

Kinematics emitJointTransforms(Emit& e) {
  const Model& m = e.model();
  Kinematics kin;
  kin.b.resize(std::size_t(m.numBodies()));
  const InScope<Kinematics> scope(e.fn.live().kin, &kin);
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

// The entries the pass left constant: runs of zeros as loops (a branch's
// entries against another branch's: 70% of a humanoid's M), the others (a
// leaf's own inertia, the base's mass) one by one. One fill of the whole
// matrix before the pass was no faster and is a memset: `rep stosb` on
// glibc, which callgrind counts by the byte (docs/benchmarks.md).
void finishMassMatrix(Emit& e, const JointSpace& js, const std::vector<char>& written) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  auto constantAt = [&](int k) {
    return !written[std::size_t(Sym::index(nv, std::min(k / nv, k % nv), std::max(k / nv, k % nv)))];
  };
  auto value = [&](int k) { return js.upper(std::min(k / nv, k % nv), std::max(k / nv, k % nv)); };
  for (int k = 0; k < nv * nv;) {
    if (!constantAt(k)) {
      ++k;
      continue;
    }
    const Expr x = value(k);
    int end = k + 1;
    if (x.isZero())
      while (end < nv * nv && constantAt(end) && value(end).isZero()) ++end;
    if (end - k > 2)
      cb.line(fmt::format("for (int k = {}; k < {}; ++k) M[k] = {};", k, end, cb.print(x)), {}, {"M"});
    else
      for (int j = k; j < end; ++j) cb.line(fmt::format("M[{}] = {};", j, cb.print(x)), {}, {"M"});
    k = end;
  }
}

// Fills js (in the caller's Live).
void compositeInertias(Emit& e, const Kinematics& kin, JointSpace& js, std::vector<char>& written) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size());
  e.fn.beginPass("", "composite inertias, leaves first: M_ji = S_j^T X^T ... Ic_i S_i");
  for (int i = N - 1; i >= 1; --i) {
    e.fn.boundary(i);
    e.openBody(i, "composite");
    CodeBuilder& cb = e.cb();
    const BodyPlan& p = e.bp(i);
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    std::vector<V6> F(std::size_t(p.nv));
    for (int d = 0; d < p.nv; ++d) {
      F[std::size_t(d)] = mul(cb, js.Ic[std::size_t(i)], kb.S[std::size_t(d)]);
      flatten(cb, F[std::size_t(d)], "F");
    }
    for (int r = 0; r < p.nv; ++r)
      for (int c = r; c < p.nv; ++c)
        putMass(e, js, written, p.idx_v + r, p.idx_v + c, dot(cb, kb.S[std::size_t(r)], F[std::size_t(c)]));
    for (int j = i; e.bp(j).parent > 0; j = e.bp(j).parent) {
      const BodyPlan& pj = e.bp(e.bp(j).parent);
      const Kinematics::Body& kj = kin.b[std::size_t(j)];
      const Kinematics::Body& kp = kin.b[std::size_t(pj.index)];
      for (int d = 0; d < p.nv; ++d) {
        F[std::size_t(d)] = e.forceToParent(kj, F[std::size_t(d)]);
        flatten(cb, F[std::size_t(d)], "F");
        for (int r = 0; r < pj.nv; ++r)  // an ancestor's dofs come first: the upper triangle
          putMass(e, js, written, pj.idx_v + r, p.idx_v + d, dot(cb, kp.S[std::size_t(r)], F[std::size_t(d)]));
      }
    }
    if (p.parent > 0) {
      const Sym dI = e.inertiaToParent(kb, js.Ic[std::size_t(i)]);
      Sym& par = js.Ic[std::size_t(p.parent)];
      for (int k = 0; k < 21; ++k)
        if (!dI.packed(k).isZero()) par.packed(k) = e.putQ(kIc, p.parent, 21, k, par.packed(k) + dI.packed(k));
    }
    cb.close();
  }
}

}  // namespace

std::string emitMassMatrix(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms) {
  JointSpace js;
  js.upper = Sym(e.plan.nv);
  for (const Kinematics::Body& b : kin.b) js.Ic.push_back(b.IA);
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().js = &js;
  e.fn.beginHost("crba", afterTransforms);
  e.cb().line("joint_transforms(q, w);", {}, {"q", "w"});
  std::vector<char> written(std::size_t(e.plan.nv * (e.plan.nv + 1) / 2), 0);
  compositeInertias(e, kin, js, written);
  finishMassMatrix(e, js, written);
  std::string text = e.fn.endHost({"q", "w", "M"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

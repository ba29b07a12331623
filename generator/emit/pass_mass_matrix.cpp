// The joint-space inertia M(q) by the composite-rigid-body algorithm, leaves
// first: F = Ic_i S_i, M_ii = S_i^T F, then F carried to each ancestor j
// (F = X^T F) gives M_ji = S_j^T F; Ic_p += X_i^T Ic_i X_i. A leaf's Ic is its
// own inertia, a constant, so its diagonal entry folds. Also the q-only joint
// transforms (joint_transforms(q, w)) that the joint-space functions without a
// velocity start from. The generic counterpart: algorithms/crba.cpp.
#include <fmt/format.h>

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

std::string massMember(Emit& e, int r, int c) {
  const int nv = e.plan.nv;
  return e.member("mass", nv * (nv + 1) / 2, Sym::index(nv, r, c), "joint-space inertia M (upper triangle, by rows)");
}

// Fills js (in the caller's Live).
void compositeInertias(Emit& e, const Kinematics& kin, JointSpace& js) {
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
        js.upper(p.idx_v + r, p.idx_v + c) =
            e.put(massMember(e, p.idx_v + r, p.idx_v + c), dot(cb, kb.S[std::size_t(r)], F[std::size_t(c)]));
    for (int j = i; e.bp(j).parent > 0; j = e.bp(j).parent) {
      const BodyPlan& pj = e.bp(e.bp(j).parent);
      const Kinematics::Body& kj = kin.b[std::size_t(j)];
      const Kinematics::Body& kp = kin.b[std::size_t(pj.index)];
      for (int d = 0; d < p.nv; ++d) {
        F[std::size_t(d)] = e.forceToParent(kj, F[std::size_t(d)]);
        flatten(cb, F[std::size_t(d)], "F");
        for (int r = 0; r < pj.nv; ++r)  // an ancestor's dofs come first: the upper triangle
          js.upper(pj.idx_v + r, p.idx_v + d) =
              e.put(massMember(e, pj.idx_v + r, p.idx_v + d), dot(cb, kp.S[std::size_t(r)], F[std::size_t(d)]));
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

void copyOutSymmetric(Emit& e, const Sym& upper, const char* out) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  for (int r = 0; r < nv; ++r)
    for (int c = 0; c < nv; ++c)
      cb.line(fmt::format("{}[{}] = {};", out, r * nv + c, cb.print(upper(r, c))), {upper(r, c)}, {out});
}

std::string emitMassMatrix(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms) {
  JointSpace js;
  js.upper = Sym(e.plan.nv);
  for (const Kinematics::Body& b : kin.b) js.Ic.push_back(b.IA);
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().js = &js;
  e.fn.beginHost("crba", afterTransforms);
  e.cb().line("joint_transforms(q, w);", {}, {"q", "w"});
  compositeInertias(e, kin, js);
  copyOutSymmetric(e, js.upper, "M");
  std::string text = e.fn.endHost({"q", "w", "M"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

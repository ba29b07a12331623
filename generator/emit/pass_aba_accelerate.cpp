// The forward pass of ABA, root first: a'_i = X_i a_p + c_i,
// qdd_i = D^-1 (u_i - U^T a'_i), a_i = a'_i + S qdd_i. Both algorithms use it
// (proxPV with the multiplier terms in u). The generic counterpart:
// algorithms/aba.cpp.
#include <fmt/format.h>

#include <stdexcept>

#include "emit/passes.hpp"

namespace proxgen::emit {

void accelerateBody(Emit& e, const Kinematics& kin, const Articulated& art, int i, const std::vector<Expr>& uEff,
                    bool storeQdd, Motion& motion) {
  CodeBuilder& cb = e.cb();
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const Articulated::Body& b = art.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  V6 ap = add(e.motionToChild(kb, p.parent == 0 ? e.rootAcceleration() : motion.a[std::size_t(p.parent)]), kb.c);
  flatten(cb, ap, "t");  // used twice: in U^T a' and in a
  const int n = p.nv;
  std::vector<Expr> r(static_cast<std::size_t>(n));
  for (int d = 0; d < n; ++d) r[std::size_t(d)] = uEff[std::size_t(d)] - dot(cb, b.U[std::size_t(d)], ap);
  std::vector<Expr> qdd(static_cast<std::size_t>(n));
  if (n == 1) qdd[0] = cb.mul(b.Dinv, cb.flat(r[0]));
  else qdd = choleskySolve(cb, b.L, b.Linv, r);
  V6 a = ap;
  for (int d = 0; d < n; ++d) {
    if (storeQdd)
      motion.qdd[std::size_t(p.idx_v + d)] = qdd[std::size_t(d)] =
          e.put(e.member("qdd", e.plan.nv, p.idx_v + d, "joint accelerations"), qdd[std::size_t(d)]);
    a = add(a, scale(cb, qdd[std::size_t(d)], kb.S[std::size_t(d)]));
  }
  const bool needed = !p.children.empty() || !p.constraints.empty();
  for (int k = 0; k < 6; ++k)
    motion.a[std::size_t(i)][std::size_t(k)] = needed ? e.putQ(kA, i, 6, k, a[std::size_t(k)]) : a[std::size_t(k)];
}

void accelerateSupport(Emit& e, const Kinematics& kin, const Articulated& art, Motion& motion) {
  for (int i : e.plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "accelerate");
    accelerateBody(e, kin, art, i, art.b[std::size_t(i)].u, true, motion);
    e.cb().close();
  }
}

namespace {

std::string accelerations(const CodeBuilder& cb, const std::vector<int>& bodies, const Motion& motion) {
  std::string f;
  for (int i : bodies)
    for (const Expr& x : motion.a[std::size_t(i)]) f += cb.describe(x) + ";";
  return f;
}

// accelerate_free_bodies, as a host of its own, from copies of the caller's state.
void emitAccelerateFree(Emit& e, Kinematics kin, Articulated art, Motion motion, FreeAccelerations& out) {
  const Live saved = e.fn.live();
  e.fn.live() = Live{&kin, &art, &motion};
  e.fn.beginHost("accelerate_free", e.fn.current());
  for (int i : e.plan.offSupport) {
    e.fn.boundary(i);
    e.openBody(i, "accelerate");
    accelerateBody(e, kin, art, i, art.b[std::size_t(i)].u, true, motion);
    e.cb().close();
  }
  out.text = e.fn.endHost({"w"});
  out.builder = e.fn.lastHost();
  out.out = std::move(motion);
  e.fn.live() = saved;
}

}  // namespace

void callAccelerateFree(Emit& e, const Kinematics& kin, const Articulated& art, Motion& motion) {
  e.fn.endPart();
  if (e.plan.offSupport.empty()) return;  // no function to call
  FreeAccelerations& fa = *e.freeAccel;
  if (!fa.builder) {
    fa.supportAccelerations = accelerations(e.cb(), e.plan.support, motion);
    emitAccelerateFree(e, kin, art, motion, fa);
  } else if (accelerations(e.cb(), e.plan.support, motion) != fa.supportAccelerations) {
    // accelerate_free_bodies reads the support accelerations as members: they
    // must be the same members in both algorithms.
    throw std::logic_error("emitter: the support accelerations differ between the two algorithms");
  }
  e.cb().line("accelerate_free_bodies(w);", {}, {"w"});
  std::vector<int> cache;
  for (int i : e.plan.offSupport)
    for (int d = 0; d < e.bp(i).nv; ++d) {
      const std::size_t j = std::size_t(e.bp(i).idx_v + d);
      motion.qdd[j] = e.cb().import(*fa.builder, fa.out.qdd[j], cache);
    }
}

}  // namespace proxgen::emit

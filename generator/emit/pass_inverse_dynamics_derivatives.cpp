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
// host copies the nonzero entries out and writes the zeros.
// The generic counterpart: algorithms/derivatives.cpp (tangentSweep).
#include <fmt/format.h>

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

Col save(Emit& e, const Quantity& qy, int body, int col, const V6& x) {
  Col s;
  for (int r = 0; r < 6; ++r) {
    const Expr& v = x[std::size_t(r)];
    if (v.isConstant()) {
      s[std::size_t(r)].value = v;
    } else {
      s[std::size_t(r)].name = e.member(qy, body, 6, e.plan.nv, r, col);
      e.cb().store(s[std::size_t(r)].name, v);
    }
  }
  return s;
}

std::string vIn(int k) { return fmt::format("v[{}]", k); }
std::string qddIn(int k) { return fmt::format("qdd[{}]", k); }
std::string lambdaIn(int k) { return fmt::format("lambda[{}]", k); }

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

// df = I da + dv x* I v + v x* I dv (I constant: I v and I dv need no products).
V6 forceTangent(Emit& e, const Kinematics::Body& kb, const V6& da, const V6& dv) {
  CodeBuilder& cb = e.cb();
  const V6 Ida = mul(cb, kb.IA, da);
  const V6 Iv = mul(cb, kb.IA, kb.v);
  const V6 t1 = crossForce(cb, dv, Iv);
  const V6 Idv = mul(cb, kb.IA, dv);
  const V6 t2 = crossForce(cb, kb.v, Idv);
  return add(add(Ida, t1), t2);
}

// The forward tangents of one column k of body i, given its q and v motion
// tangents before the velocity-product term; stores what the children and the
// backward sweep read.
void finishColumn(Emit& e, const Kinematics::Body& kb, int i, int k, const V6& vJ, const V6& dvq, const V6& dvv,
                  const V6& daq0, const V6& dav0, bool store, Sweep& s) {
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
    s.dvq[b][k] = save(e, kDvq, i, k, dq);
    s.dvv[b][k] = save(e, kDvv, i, k, dv);
    s.daq[b][k] = save(e, kDaq, i, k, daq);
    s.dav[b][k] = save(e, kDav, i, k, dav);
  }
  const V6 fq = forceTangent(e, kb, daq, dq);
  s.dfq[b][k] = save(e, kDfq, i, k, fq);
  const V6 fv = forceTangent(e, kb, dav, dv);
  s.dfv[b][k] = save(e, kDfv, i, k, fv);
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
      if (withLambda)
        for (int k : p.constraints) {
          const Constraint& c = e.sys.constraints[std::size_t(k)];
          const Mat6 X = c.placement.motionMatrixInv();  // rows K_c: body motion -> constraint frame
          for (int r = 0; r < 6; ++r)
            for (int j = 0; j < c.rows(); ++j)
              if (X(j, r) != 0) f[std::size_t(r)] += X(j, r) * cb.input(lambdaIn(c.row + j));
        }
      for (int k = 0; k < 6; ++k) fs.f[std::size_t(i)][std::size_t(k)] = e.putQ(kF, i, 6, k, f[std::size_t(k)]);
      const V6 vJ = jointVelocity(e, kb, p);
      const V6 vp = sub(kb.v, vJ);  // X^-1 v_p
      for (int d = 0; d < p.nv; ++d) {
        const V6& Sk = kb.S[std::size_t(d)];
        const V6 dvq = crossMotion(cb, vp, Sk);
        const V6 daq = crossMotion(cb, ap, Sk);
        const V6 dav = crossMotion(cb, kb.v, Sk);
        finishColumn(e, kb, i, p.idx_v + d, vJ, dvq, Sk, daq, dav, store, s);
      }
    }
    e.cb().close();
    // The ancestors' columns, carried from the parent: one block each.
    if (p.parent <= 0) continue;
    const std::size_t par = std::size_t(p.parent);
    for (const auto& [k, unused] : s.dvq[par]) {
      static_cast<void>(unused);
      e.fn.boundary(fmt::format("{}_c{}", p.ident, k));
      e.cb().open("{", {fmt::format("body {} '{}', column {}", i, p.ident, k)});
      const V6 vJ = jointVelocity(e, kb, p);
      const V6 pq = load(e.cb(), s.dvq[par].at(k));
      const V6 dvq = e.motionToChild(kb, pq);
      const V6 pv = load(e.cb(), s.dvv[par].at(k));
      const V6 dvv = e.motionToChild(kb, pv);
      const V6 paq = load(e.cb(), s.daq[par].at(k));
      const V6 daq = e.motionToChild(kb, paq);
      const V6 pav = load(e.cb(), s.dav[par].at(k));
      const V6 dav = e.motionToChild(kb, pav);
      finishColumn(e, kb, i, k, vJ, dvq, dvv, daq, dav, store, s);
      e.cb().close();
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
      for (const auto& [k, col] : cols) {
        e.fn.boundary(fmt::format("{}_c{}", p.ident, k));
        e.cb().open("{", {fmt::format("body {} '{}', {} column {}", i, p.ident, pass == 0 ? "q" : "v", k)});
        CodeBuilder& cb = e.cb();
        V6 df = load(cb, col);
        for (int d = 0; d < p.nv; ++d) {
          const int row = p.idx_v + d;
          const Expr t = dot(cb, kb.S[std::size_t(d)], df);
          Slot slot;
          if (t.isConstant()) {
            slot.value = t;
          } else {
            slot.name = e.ws.member(pass == 0 ? "dtau_dq" : "dtau_dv", nv, nv, row, k, "d tau / dq or d tau / dv (row-major)");
            cb.store(slot.name, t);
          }
          (pass == 0 ? out.dq : out.dv)[{row, k}] = slot;
        }
        if (p.parent > 0) {
          if (pass == 0 && k >= p.idx_v && k < p.idx_v + p.nv) {
            const V6 carried = crossForce(cb, kb.S[std::size_t(k - p.idx_v)], fs.f[b]);
            df = add(df, carried);
          }
          const V6 dp = e.forceToParent(kb, df);
          Cols& pc = pass == 0 ? s.dfq[par] : s.dfv[par];
          V6 sum = dp;
          if (const auto it = pc.find(k); it != pc.end()) {
            const V6 old = load(cb, it->second);
            sum = add(old, dp);
          }
          pc[k] = save(e, pass == 0 ? kDfq : kDfv, p.parent, k, sum);
        }
        cb.close();
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

// out[r * nv + c] for every entry: zeros by a loop, then the nonzero ones.
void copyOut(Emit& e, const std::map<std::pair<int, int>, Slot>& entries, const char* out) {
  CodeBuilder& cb = e.cb();
  const int nv = e.plan.nv;
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = Scalar(0);", nv * nv, out), {}, {out});
  for (const auto& [rc, slot] : entries) {
    const Expr x = slot.name.empty() ? slot.value : cb.member(slot.name);
    if (x.isZero()) continue;
    cb.line(fmt::format("{}[{}] = {};", out, rc.first * nv + rc.second, cb.print(x)), {x}, {out});
  }
}

}  // namespace

V6 load(CodeBuilder& cb, const TangentCol& s) {
  V6 x;
  for (std::size_t r = 0; r < 6; ++r) x[r] = s[r].name.empty() ? s[r].value : cb.member(s[r].name);
  return x;
}

std::string emitInverseDynamicsDerivatives(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics,
                                           BodyTangents* keep) {
  const Plan& plan = e.plan;
  const bool withLambda = plan.nc > 0;
  const int N = int(plan.bodies.size());
  Forces forces{std::vector<V6>(std::size_t(N), zero6()), std::vector<V6>(std::size_t(N), zero6()),
                std::vector<Expr>(std::size_t(plan.nv))};
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
  host.line("kinematics(q, v, w);", {}, {"q", "v", "w"});
  forward(e, kin, withLambda, keep != nullptr, forces, s);
  if (keep != nullptr) *keep = BodyTangents{s.dvq, s.dvv, s.daq, s.dav};
  backward(e, kin, forces, s, out);
  e.fn.endPart();
  copyOut(e, out.dq, "dtau_dq");
  copyOut(e, out.dv, "dtau_dv");
  std::string text = e.fn.endHost({"q", "v", "qdd", "lambda", "w", "dtau_dq", "dtau_dv"});
  e.fn.live() = Live{};
  return text;
}

// The arithmetic of dense_product<n, m, p> (assemble.cpp prints it): per row
// r and k, the scaling s A_rk, then p multiply-adds into C's row.
Ops denseProductOps(int n, int m, int p) {
  Ops o;
  o.mul = long(n) * m * (p + 1);
  o.add = long(n) * m * p;
  return o;
}

std::string emitForwardDynamicsDerivatives(Emit& e) {
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
  e.fn.live() = Live{};
  e.fn.beginHost("fdd", nullptr);
  CodeBuilder& cb = e.cb();
  const std::vector<std::string> names = {"q", "v", "tau", "w", "qdd", "dqdd_dq", "dqdd_dv", "dqdd_dtau"};
  OpCount ops;
  cb.line(fmt::format("nonlinear_effects(q, v, w, {});", h), {}, names);
  cb.line("mass_matrix_inverse(q, w, dqdd_dtau);", {}, names);
  // h := tau - h, then qdd = M^-1 (tau - h): ABA's answer to round-off.
  ops.once = Ops{};
  ops.once.add = nv;
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = tau[k] - {}[k];", nv, h, h), {}, names, ops);
  ops.once = denseProductOps(nv, nv, 1);
  cb.line(fmt::format("dense_product<{0}, {0}, 1>(dqdd_dtau, {1}, Scalar(1), qdd);", nv, h), {}, names, ops);
  cb.line(fmt::format("inverse_dynamics_derivatives(q, v, qdd, nullptr, w, {}, {});", dq, dv), {}, names);
  ops.once = denseProductOps(nv, nv, nv);
  cb.line(fmt::format("dense_product<{0}, {0}, {0}>(dqdd_dtau, {1}, Scalar(-1), dqdd_dq);", nv, dq), {}, names, ops);
  cb.line(fmt::format("dense_product<{0}, {0}, {0}>(dqdd_dtau, {1}, Scalar(-1), dqdd_dv);", nv, dv), {}, names, ops);
  return e.fn.endHost(names);
}

}  // namespace proxgen::emit

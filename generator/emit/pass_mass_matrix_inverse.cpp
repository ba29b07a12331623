// M(q)^-1 in O(n^2) without factoring M: ABA on the nv unit torques at once,
// with v = 0 and no gravity (docs/dynamics.md). Body i has dofs [s, s + n) and
// subtree dofs [s, e). Backward, leaves first, F_i[:, j] the unit-torque bias
// force (zero unless j is in i's subtree):
//   Minv(s, s) = D^-1; Minv(s, j) = -D^-1 S^T F_i[:, j] (s < j < e);
//   F_i[:, j] += U Minv(s, j); F_p[:, j] += X^T F_i[:, j]; IA_p += X^T Ia X.
// Forward, root first, for every column j >= s (the upper triangle):
//   a' = X A_p[:, j]; Minv(s, j) -= D^-1 U^T a'; A_i[:, j] = a' + S Minv(s, j).
// F_i and A_i share the member FA_<body> (the forces are last read before the
// accelerations are written), and the lower triangle is the mirror. The free
// flyer (always the root) uses the Cholesky factor of its 6 x 6 IA for D^-1.
// The generic counterpart: algorithms/mass_matrix_inverse.cpp.
#include <fmt/format.h>

#include <algorithm>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

std::string minvMember(Emit& e, int r, int c) {
  const int nv = e.plan.nv;
  return e.member("minv", nv * (nv + 1) / 2, Sym::index(nv, r, c), "M^-1 (upper triangle, by rows)");
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

void backwardOneDof(Emit& e, const Kinematics& kin, int i, int end, Articulated& art, JointSpace& js) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v;
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
  std::vector<V6>& F = js.FA[std::size_t(i)];
  js.upper(s, s) = b.Dinv;
  for (int j = s + 1; j < end; ++j)
    js.upper(s, j) = e.put(minvMember(e, s, j), -cb.mul(b.Dinv, cb.flat(dot(cb, S, F[std::size_t(j)]))));
  if (p.parent == 0) return;  // nothing passes on: the forward pass reads only Minv
  std::vector<V6>& Fp = js.FA[std::size_t(p.parent)];
  for (int j = s; j < end; ++j) {
    V6 f;
    for (int r = 0; r < 6; ++r)
      f[std::size_t(r)] = F[std::size_t(j)][std::size_t(r)] + cb.mul(b.U[0][std::size_t(r)], js.upper(s, j));
    flatten(cb, f, "f");
    const V6 dp = e.forceToParent(kb, f);
    for (int r = 0; r < 6; ++r)
      if (!dp[std::size_t(r)].isZero())
        Fp[std::size_t(j)][std::size_t(r)] = e.keepQ(kFA, p.parent, 6, e.plan.nv, r, j, Fp[std::size_t(j)][std::size_t(r)] + dp[std::size_t(r)]);
  }
  passInertia(e, kin, i, art);
}

// The free flyer at the root: D^-1 = IA^-1 through its Cholesky factor.
void backwardFreeFlyer(Emit& e, int i, int end, Articulated& art, JointSpace& js) {
  CodeBuilder& cb = e.cb();
  Articulated::Body& b = art.b[std::size_t(i)];
  const int s = e.bp(i).idx_v;
  const Cholesky ch = cholesky(
      e, b.IA, Expr(), [&](int r, int c) { return e.member(kL, i, 21, Sym::index(6, r, c)); },
      [&](int r) { return e.member(kLinv, i, 6, r); });
  const auto solve = [&](const std::vector<Expr>& rhs) {
    return backwardSolve(cb, ch.L, ch.inv, forwardSolve(cb, ch.L, ch.inv, rhs));
  };
  for (int c = 0; c < 6; ++c) {
    std::vector<Expr> unit(6);
    unit[std::size_t(c)] = Expr(1.0);
    const std::vector<Expr> x = solve(unit);
    for (int r = 0; r <= c; ++r) js.upper(s + r, s + c) = e.put(minvMember(e, s + r, s + c), x[std::size_t(r)]);
  }
  for (int j = s + 6; j < end; ++j) {
    const V6& F = js.FA[std::size_t(i)][std::size_t(j)];
    const std::vector<Expr> x = solve(std::vector<Expr>(F.begin(), F.end()));
    for (int r = 0; r < 6; ++r) js.upper(s + r, j) = e.put(minvMember(e, s + r, j), -x[std::size_t(r)]);
  }
}

void forwardBody(Emit& e, const Kinematics& kin, int i, const Articulated& art, JointSpace& js) {
  CodeBuilder& cb = e.cb();
  const BodyPlan& p = e.bp(i);
  const int s = p.idx_v, nv = e.plan.nv;
  const bool store = !p.children.empty();  // A_i is read by the children only
  std::vector<V6>& A = js.FA[std::size_t(i)];
  if (p.jointClass == JointClass::FreeFlyer) {  // the root: a' = 0, A = S Minv(s.., j) with S = I
    for (int j = s; j < nv; ++j)
      for (int r = 0; r < 6; ++r) A[std::size_t(j)][std::size_t(r)] = store ? js.upper(s + r, j) : Expr();
    return;
  }
  const Articulated::Body& b = art.b[std::size_t(i)];
  const Kinematics::Body& kb = kin.b[std::size_t(i)];
  for (int j = s; j < nv; ++j) {
    V6 a = zero6();
    if (p.parent > 0) {
      a = e.motionToChild(kb, js.FA[std::size_t(p.parent)][std::size_t(j)]);
      flatten(cb, a, "t");
      const Expr x = js.upper(s, j) - cb.mul(b.Dinv, cb.flat(dot(cb, b.U[0], a)));
      js.upper(s, j) = e.put(minvMember(e, s, j), x);
    }
    if (!store) continue;
    const V6 Aj = add(a, scale(cb, js.upper(s, j), kb.S[0]));
    for (int r = 0; r < 6; ++r) A[std::size_t(j)][std::size_t(r)] = e.keepQ(kFA, i, 6, nv, r, j, Aj[std::size_t(r)]);
  }
}

}  // namespace

std::string emitMassMatrixInverse(Emit& e, Kinematics kin, const CodeBuilder* afterTransforms) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size());
  // Subtree dof ends: depth-first order makes a subtree's dofs contiguous.
  std::vector<int> end(std::size_t(N), 0);
  for (int i = N - 1; i >= 1; --i) {
    const BodyPlan& p = e.bp(i);
    end[std::size_t(i)] = std::max(end[std::size_t(i)], p.idx_v + p.nv);
    if (p.parent > 0) end[std::size_t(p.parent)] = std::max(end[std::size_t(p.parent)], end[std::size_t(i)]);
  }
  Articulated art = startElimination(kin);  // IA = I, pA = 0 (the transforms pass sets no bias)
  JointSpace js;
  js.upper = Sym(plan.nv);
  js.FA.assign(std::size_t(N), std::vector<V6>(std::size_t(plan.nv), zero6()));
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().art = &art;
  e.fn.live().js = &js;
  e.fn.beginHost("minv", afterTransforms);
  e.cb().line("joint_transforms(q, w);", {}, {"q", "w"});
  e.fn.beginPass("backward", "backward: D^-1 and the unit-torque forces, leaves first");
  for (int i = N - 1; i >= 1; --i) {
    e.fn.boundary(i);
    e.openBody(i, "eliminate");
    if (e.bp(i).jointClass == JointClass::FreeFlyer) backwardFreeFlyer(e, i, end[std::size_t(i)], art, js);
    else backwardOneDof(e, kin, i, end[std::size_t(i)], art, js);
    e.cb().close();
  }
  e.fn.beginPass("forward", "forward: the unit-torque accelerations, the upper triangle of M^-1");
  for (int i = 1; i < N; ++i) {
    e.fn.boundary(i);
    e.openBody(i, "accelerate");
    forwardBody(e, kin, i, art, js);
    e.cb().close();
  }
  copyOutSymmetric(e, js.upper, "Minv");
  std::string text = e.fn.endHost({"q", "w", "Minv"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

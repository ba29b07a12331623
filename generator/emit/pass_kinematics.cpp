// The kinematics pass: per body its joint transform, velocity, velocity-product
// acceleration, bias force v x* I v, gravity in body coordinates (support) and
// world placement (under a kp constraint); per constraint its right-hand side
// k (docs/algorithms.md §2). Where sincos is inlined (sincosCalled), all the
// joint transforms come first, a pass of their own: the iiwa's solvers take
// 0.90-0.93 of the time so, nonlinear_effects 0.74-0.81 on the iiwa and Solo
// (docs/benchmarks.md). The generic counterpart: algorithms/kinematics.cpp,
// algorithms/constraints.cpp.
#include <fmt/format.h>

#include <algorithm>

#include "emit/identifiers.hpp"
#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

std::string q(int k) { return fmt::format("q[{}]", k); }
std::string vIn(int k) { return fmt::format("v[{}]", k); }
Ops sincos() {
  Ops o;
  o.sincos = 1;
  return o;
}

bool revolute(const BodyPlan& b) {
  return b.jointClass == JointClass::RevoluteX || b.jointClass == JointClass::RevoluteY ||
         b.jointClass == JointClass::RevoluteZ || b.jointClass == JointClass::RevoluteAxis;
}

// The revolute joints' bodies in q order: slot j of w.sq and w.cq is the j-th.
std::vector<int> revoluteBodies(const Plan& plan) {
  std::vector<int> out;
  for (std::size_t i = 1; i < plan.bodies.size(); ++i)  // bodies[0] is the world
    if (revolute(plan.bodies[i])) out.push_back(int(i));
  std::sort(out.begin(), out.end(),
            [&](int a, int b) { return plan.bodies[std::size_t(a)].idx_q < plan.bodies[std::size_t(b)].idx_q; });
  return out;
}

// The members holding joint j's sine and cosine.
std::pair<std::string, std::string> sincosMembers(Emit& e, int slot, int slots) {
  return {e.member("sq", slots, slot, "sin q of the revolute joints (q order)"),
          e.member("cq", slots, slot, "cos q of the revolute joints (q order)")};
}

}  // namespace

bool sincosCalled(const Plan& plan) { return revoluteBodies(plan).size() > kSincosInlinedUpTo; }

void sincosRuns(Emit& e, bool supportOnly) {
  const std::vector<int> all = revoluteBodies(e.plan);
  auto wanted = [&](std::size_t j) { return !supportOnly || e.bp(all[j]).onSupport; };
  CodeBuilder& cb = e.cb();
  for (std::size_t a = 0; a < all.size();) {
    if (!wanted(a)) {
      ++a;
      continue;
    }
    // The run: consecutive slots whose angles are consecutive in q.
    std::size_t b = a + 1;
    while (b < all.size() && wanted(b) && e.bp(all[b]).idx_q == e.bp(all[b - 1]).idx_q + 1)
      ++b;
    std::vector<std::string> written;
    std::vector<Expr> angles;
    for (std::size_t j = a; j < b; ++j) {
      const auto [sm, cm] = sincosMembers(e, int(j), int(all.size()));
      written.push_back(sm);
      written.push_back(cm);
      angles.push_back(cb.input(q(e.bp(all[j]).idx_q)));
    }
    // `true`: the joints after it call sincos (sincos_joint_called), which the
    // runtime replaces by the run in more targets (two lanes as well, lanes.hpp).
    cb.storeByCall(fmt::format("proxgen_rt::sincos_run<{}{}>(&{}, &{}, &{});", b - a,
                               sincosCalled(e.plan) ? ", true" : "", q(e.bp(all[a]).idx_q), written[0], written[1]),
                   written, angles);
    a = b;
  }
}

bool jointTransformsFirst(Emit& e, Kinematics& kin) {
  sincosRuns(e);
  if (sincosCalled(e.plan)) return false;
  e.fn.beginPass("transforms", "joint transforms X_J(q)");
  for (int i : e.plan.sweep) {
    e.fn.boundary(i);
    e.openBody(i, "");
    jointTransform(e, i, kin.b[std::size_t(i)]);
    e.cb().close();
  }
  return true;
}

void jointTransform(Emit& e, int i, Kinematics::Body& b) {
  const Body& body = e.model().bodies[std::size_t(i)];
  const Joint& j = body.joint;
  const BodyPlan& p = e.bp(i);
  b.XT = constant(body.treePlacement);
  b.XJ = {constant(Mat3(Mat3::Identity())), zero3()};
  const Mat6X S = e.model().motionSubspace(i);
  b.S.clear();
  for (int d = 0; d < j.nv; ++d) b.S.push_back(constant(Vec6(S.col(d))));
  CodeBuilder& cb = e.cb();
  if (p.jointClass == JointClass::FreeFlyer) {
    // q = [x y z qx qy qz qw]. The quaternion is normalised as `proxgen eval`
    // normalises it (model/state.cpp): divided by its largest magnitude (a
    // branch-free select of the runtime), so its squared norm neither
    // overflows nor underflows, then by its norm. A zero quaternion, which eval
    // refuses, gives 1 / 0 here and NaN in every output (documented in the
    // header). Then R as Eigen's Quaternion::toRotationMatrix.
    std::vector<Expr> raw;
    for (int k = 3; k < 7; ++k) raw.push_back(cb.input(q(j.idx_q + k)));
    const Expr largest = cb.define(
        "qscale",
        fmt::format("proxgen_rt::largest_magnitude({}, {}, {}, {})", cb.print(raw[0]), cb.print(raw[1]),
                    cb.print(raw[2]), cb.print(raw[3])),
        raw);
    const Expr toLargest = cb.recip(largest, "inv");
    std::vector<Expr> scaled;
    Expr norm2;
    for (const Expr& c : raw) scaled.push_back(cb.temp(cb.mul(c, toLargest), "qs"));
    for (const Expr& c : scaled) norm2 += cb.mul(c, c);
    const Expr toUnit = cb.recip(cb.sqrt(norm2, "qn"), "inv");
    std::vector<Expr> unit;
    for (const Expr& c : scaled) unit.push_back(cb.temp(cb.mul(c, toUnit), "qu"));
    const Expr &x = unit[0], &y = unit[1], &z = unit[2], &w = unit[3];
    // 2 a b + s 2 c d, the products in this order (see mulAdd in symbolic.cpp).
    auto two = [&](const Expr& a, const Expr& b2, double s, const Expr& c, const Expr& d) {
      return 2.0 * mulAdd(cb, a, b2, s, c, d);
    };
    const M3 R = {1.0 - two(y, y, 1.0, z, z), two(x, y, -1.0, w, z), two(x, z, 1.0, w, y),
                  two(x, y, 1.0, w, z), 1.0 - two(x, x, 1.0, z, z), two(y, z, -1.0, w, x),
                  two(x, z, -1.0, w, y), two(y, z, 1.0, w, x), 1.0 - two(x, x, 1.0, y, y)};
    for (int k = 0; k < 9; ++k) b.XJ.R[std::size_t(k)] = e.keepQ(kRJ, i, 3, 3, k / 3, k % 3, R[std::size_t(k)]);
    b.XJ.p = {cb.input(q(j.idx_q)), cb.input(q(j.idx_q + 1)), cb.input(q(j.idx_q + 2))};
    return;
  }
  if (p.jointClass == JointClass::Planar) {
    // q = [x y c s]; R = [c -s 0; s c 0; 0 0 1], p = [x y 0], (c, s) used as
    // given (callers normalise), as Model::jointPlacement. Kept in the
    // workspace: the backward and forward passes (other functions) need them.
    std::vector<Expr> qs;
    for (int k = 0; k < 4; ++k) qs.push_back(cb.store(e.member(kQ, i, 4, k), cb.input(q(j.idx_q + k))));
    const Expr &c = qs[2], &s = qs[3];
    b.XJ.R = {c, -s, Expr(), s, c, Expr(), Expr(), Expr(), Expr(1.0)};
    b.XJ.p = {qs[0], qs[1], Expr()};
    return;
  }
  const Vec3 a = j.axis;
  if (j.type == JointType::Prismatic) {
    // Kept in the workspace: the backward and forward passes (other functions) need it.
    const Expr qi = cb.store(e.member(kQ, i, 0, 0), cb.input(q(j.idx_q)));
    for (int k = 0; k < 3; ++k) b.XJ.p[std::size_t(k)] = a[k] * qi;
    return;
  }
  // Revolute: R = c I + s [a]x + (1 - c) a a^T; an axis along +-x/y/z folds to picks of c and s.
  // Its sine and cosine: computed here, or (a target with wide enough vector
  // registers) by the run before the pass, sincosRuns (lanes.hpp, sincos_run).
  const std::vector<int> slots = revoluteBodies(e.plan);
  const int slot = int(std::find(slots.begin(), slots.end(), i) - slots.begin());
  const auto [sm, cm] = sincosMembers(e, slot, int(slots.size()));
  const std::vector<Expr> sc = cb.storeByCall(
      fmt::format("proxgen_rt::{}({}, {}, {});", sincosCalled(e.plan) ? "sincos_joint_called" : "sincos_joint",
                  q(j.idx_q), sm, cm),
      {sm, cm}, {cb.input(q(j.idx_q))}, sincos());
  const Expr &s = sc[0], &c = sc[1];
  const Mat3 K = skew(a), A = a * a.transpose();
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) {
      const Expr x = A(r, col) + (r == col ? 1.0 : 0.0) * c - A(r, col) * c + K(r, col) * s;
      b.XJ.R[std::size_t(3 * r + col)] = p.axis >= 0 ? x : e.keepQ(kRJ, i, 3, 3, r, col, x);
    }
}

std::vector<Expr> weldError(CodeBuilder& cb, const XSym& oMc, const Constraint& c, const std::string& prefix,
                            const std::string& id) {
  const XSym E = compose(cb, constant(c.target.inverse()), oMc);
  std::vector<Expr> R, p;
  std::string Rs, ps;
  for (int j = 0; j < 9; ++j) {
    R.push_back(cb.flat(E.R[std::size_t(j)]));
    Rs += (j ? ", " : "") + cb.print(R.back());
  }
  for (int j = 0; j < 3; ++j) {
    p.push_back(cb.flat(E.p[std::size_t(j)]));
    ps += (j ? ", " : "") + cb.print(p.back());
  }
  // Each line's uses are what it prints (the operation count reads them).
  cb.line(fmt::format("const Scalar {}R_{}[9] = {{{}}};", prefix, id, Rs), R);
  cb.line(fmt::format("const Scalar {}p_{}[3] = {{{}}};", prefix, id, ps), p);
  cb.line(fmt::format("Scalar {}e_{}[6];", prefix, id));
  OpCount log6;
  log6.once.log6 = 1;
  cb.line(fmt::format("proxgen_rt::log6({0}R_{1}, {0}p_{1}, {0}e_{1});", prefix, id), {}, {}, log6);
  std::vector<Expr> e;
  for (int j = 0; j < 6; ++j) e.push_back(cb.input(fmt::format("{}e_{}[{}]", prefix, id, j)));
  return e;
}

void storeBiasForce(Emit& e, int i, Kinematics::Body& b) {
  CodeBuilder& cb = e.cb();
  V6 h = mul(cb, b.IA, b.v);
  flatten(cb, h, "h");
  const V6 pA = crossForce(cb, b.v, h);
  for (int k = 0; k < 6; ++k) b.pA[std::size_t(k)] = e.putQ(kPA, i, 6, k, pA[std::size_t(k)]);
}

namespace {

void velocity(Emit& e, int i, const Kinematics::Body& parent, Kinematics::Body& b) {
  const Joint& j = e.model().bodies[std::size_t(i)].joint;
  CodeBuilder& cb = e.cb();
  V6 vJ = zero6();
  for (int d = 0; d < j.nv; ++d) vJ = add(vJ, scale(cb, cb.input(vIn(j.idx_v + d)), b.S[std::size_t(d)]));
  const V6 v = add(e.motionToChild(b, parent.v), vJ);
  for (int k = 0; k < 6; ++k) b.v[std::size_t(k)] = e.keepQ(kV, i, 6, k, v[std::size_t(k)]);
  const V6 c = crossMotion(cb, b.v, vJ);
  for (int k = 0; k < 6; ++k) b.c[std::size_t(k)] = e.keepQ(kC, i, 6, k, c[std::size_t(k)]);
  // pA = v x* (I v); IA starts as the body's own inertia (a constant).
  b.IA = constant(e.model().bodies[std::size_t(i)].inertia.matrix());
  storeBiasForce(e, i, b);
}

void gravityAndPlacement(Emit& e, int i, const Kinematics::Body& parent, Kinematics::Body& b) {
  if (e.bp(i).needsGravity) {
    const V3 g = rotateT(e.cb(), b.XJ.R, rotateT(e.cb(), b.XT.R, parent.g));
    for (int k = 0; k < 3; ++k) b.g[std::size_t(k)] = e.keepQ(kG, i, 3, k, g[std::size_t(k)]);
  }
  if (e.bp(i).needsPlacement) {
    const XSym M = compose(e.cb(), compose(e.cb(), parent.oM, b.XT), b.XJ);
    for (int k = 0; k < 9; ++k)
      b.oM.R[std::size_t(k)] = e.keepQ(kOR, i, 3, 3, k / 3, k % 3, e.cb().flat(M.R[std::size_t(k)]));
    for (int k = 0; k < 3; ++k) b.oM.p[std::size_t(k)] = e.keepQ(kOP, i, 3, k, e.cb().flat(M.p[std::size_t(k)]));
  }
}

// k = a_star - drift - K X_{i,0} a_g (docs/algorithms.md §2), as constraints.cpp computes it.
std::vector<Expr> constraintTerms(Emit& e, int k, const Kinematics::Body& b) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const ConstraintPlan& cp = e.plan.constraints[std::size_t(k)];
  CodeBuilder& cb = e.cb();
  const int r = c.rows();
  cb.comment(fmt::format("constraint '{}' ({}) on link '{}': rows {}..{}", escapeComment(c.name), cp.weld ? "6d" : "3d",
                         escapeComment(c.link), c.row, c.row + r - 1));
  const V6 vC = actInvMotion(cb, constant(c.placement), b.v);  // twist of the constraint frame
  std::vector<Expr> kk(static_cast<std::size_t>(r));
  if (c.kd != 0)
    for (int j = 0; j < r; ++j) kk[std::size_t(j)] -= c.kd * vC[std::size_t(j)];
  if (c.kp != 0) {
    const XSym oMc = compose(cb, b.oM, constant(c.placement));
    std::vector<Expr> err(static_cast<std::size_t>(r));
    if (cp.weld) {
      err = weldError(cb, oMc, c, "kp", cp.ident);
    } else {
      V3 d;
      for (int j = 0; j < 3; ++j) d[std::size_t(j)] = oMc.p[std::size_t(j)] - c.target.p[j];
      const V3 er = rotateT(cb, oMc.R, d);
      err.assign(er.begin(), er.end());
    }
    for (int j = 0; j < r; ++j) kk[std::size_t(j)] -= c.kp * err[std::size_t(j)];
  }
  if (!cp.weld) {
    const V3 drift = cross(cb, ang(vC), lin(vC));  // w_C x v_C
    for (int j = 0; j < 3; ++j) kk[std::size_t(j)] -= drift[std::size_t(j)];
  }
  const std::vector<Expr> Kg = e.constraintRows(k, stack(b.g, zero3()));
  std::vector<Expr> out(static_cast<std::size_t>(r));
  for (int j = 0; j < r; ++j) out[std::size_t(j)] = e.keep(e.kMember(k, j), kk[std::size_t(j)] - Kg[std::size_t(j)]);
  return out;
}

}  // namespace

Kinematics emitKinematics(Emit& e) {
  const Model& m = e.model();
  Kinematics kin;
  kin.b.resize(std::size_t(m.numBodies()));
  kin.k.resize(e.sys.constraints.size());
  const InScope<Kinematics> scope(e.fn.live().kin, &kin);
  // World: at rest, gravity as given, at the origin.
  kin.b[0].g = constant(m.gravity);
  kin.b[0].oM = constant(SE3::Identity());
  const bool transformsFirst = jointTransformsFirst(e, kin);
  if (transformsFirst) e.fn.beginPass("", "velocities, bias forces, gravity, placements, constraint terms");
  for (int i : e.plan.sweep) {
    e.fn.boundary(i);
    e.openBody(i, "");
    Kinematics::Body& b = kin.b[std::size_t(i)];
    const Kinematics::Body& parent = kin.b[std::size_t(e.bp(i).parent)];
    if (!transformsFirst) jointTransform(e, i, b);
    velocity(e, i, parent, b);
    gravityAndPlacement(e, i, parent, b);
    for (int k : e.bp(i).constraints) kin.k[std::size_t(k)] = constraintTerms(e, k, b);
    e.cb().close();
  }
  if (!e.bp(0).constraints.empty()) {
    e.fn.boundary("world");
    e.cb().open("{", {"constraints on the world"});
    for (int k : e.bp(0).constraints) kin.k[std::size_t(k)] = constraintTerms(e, k, kin.b[0]);
    e.cb().close();
  }
  return kin;
}

}  // namespace proxgen::emit

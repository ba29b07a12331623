// Inverse dynamics (RNEA) with the constraint forces, root first then leaves
// first: a_i = X_i a_p + S qdd_i + c_i (a_0 = -g), f_i = I_i a_i + v_i x* I_i v_i
// (+ K_c^T lambda_c for each constraint c on body i: its rows applied as a
// wrench at its frame, [linear; angular] for a weld, linear for a point, the
// rows the solvers use), tau_i = S^T f_i, f_p += X_i^T f_i. So
// tau = M qdd + h + J^T lambda (the constraint force on the robot is -J^T lambda).
// The constraint forces enter the same backward sweep as the inertial ones
// (the generic code adds them in a second one): the sum is the same, in
// another order. The generic counterpart: algorithms/inverse_dynamics.cpp and
// algorithms/rnea.cpp (docs/dynamics.md).
#include <fmt/format.h>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

std::string qddIn(int k) { return fmt::format("qdd[{}]", k); }
std::string vIn(int k) { return fmt::format("v[{}]", k); }
std::string lambdaIn(int k) { return fmt::format("lambda[{}]", k); }

}  // namespace

void addConstraintForces(Emit& e, int i, V6& f) {
  CodeBuilder& cb = e.cb();
  for (int k : e.bp(i).constraints) {
    const Constraint& c = e.sys.constraints[std::size_t(k)];
    const Mat6 X = c.placement.motionMatrixInv();  // rows K_c: body motion -> constraint frame
    for (int r = 0; r < 6; ++r)
      for (int j = 0; j < c.rows(); ++j)
        if (X(j, r) != 0) f[std::size_t(r)] += X(j, r) * cb.input(lambdaIn(c.row + j));
  }
}

namespace {

// The forward sweep from the kinematics pass's state (nonlinear_effects:
// forward_dynamics_derivatives reads the state that pass leaves). Fills `out`
// (in scope: the caller's Live holds it).
void forwardFromKinematics(Emit& e, const Kinematics& kin, Forces& out) {
  const int N = int(e.plan.bodies.size());
  e.fn.beginPass("forward", "forward: a = X a_parent + c, f = I a + v x* I v");
  for (int i = 1; i < N; ++i) {
    e.fn.boundary(i);
    e.openBody(i, "forward");
    CodeBuilder& cb = e.cb();
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    V6 a = add(e.motionToChild(kb, p.parent == 0 ? e.rootAcceleration() : out.a[std::size_t(p.parent)]), kb.c);
    flatten(cb, a, "t");  // used in I a and by the children
    if (!p.children.empty())
      for (int k = 0; k < 6; ++k) out.a[std::size_t(i)][std::size_t(k)] = e.putQ(kA, i, 6, k, a[std::size_t(k)]);
    const V6 f = add(mul(cb, kb.IA, a), kb.pA);
    for (int k = 0; k < 6; ++k) out.f[std::size_t(i)][std::size_t(k)] = e.putQ(kF, i, 6, k, f[std::size_t(k)]);
    cb.close();
  }
}

// The forward sweep of inverse_dynamics, from q, v and qdd alone: per body its
// joint transform, v = X v_p + S qd, c = v x S qd, a = X a_p + S qdd + c and
// f = I a + v x* I v. The solvers' kinematics pass, which this replaced here,
// also stores c and v x* I v for a later function, gravity in every support
// body and the constraints' right-hand sides, none of which RNEA reads; here c
// and the bias stay in registers, and v and a are stored only for bodies with
// children. Where sincos is inlined (sincosCalled), the joint transforms come
// first, a pass of their own; where it is called (the larger robots), each in
// its body's step. Measured both ways (docs/benchmarks.md, "Revisited and kept
// for inverse_dynamics"): first, the iiwa and Solo take 0.73-0.77 of the time of
// the kinematics pass and the forward sweep, but Talos and the Atlas 1.04-1.12;
// in each step, the iiwa and Solo 1.13-1.18, Talos 0.99 and the Atlas 0.92-0.94.
// Fills `kin` (the joint transforms the backward sweep reads) and `out`, both
// in the caller's Live.
void forwardFused(Emit& e, bool withLambda, Kinematics& kin, Forces& out) {
  const int N = int(e.plan.bodies.size());
  const bool transformsFirst = jointTransformsFirst(e, kin);
  e.fn.beginPass("forward", std::string("forward: ") + (transformsFirst ? "" : "X_J(q), ") +
                                "v = X v_parent + S qd, a = X a_parent + S qdd + v x S qd, f = I a + v x* I v" +
                                (withLambda ? " + K^T lambda" : ""));
  for (int i = 1; i < N; ++i) {
    e.fn.boundary(i);
    e.openBody(i, "forward");
    CodeBuilder& cb = e.cb();
    Kinematics::Body& b = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    const bool parentOfSome = !p.children.empty();
    if (!transformsFirst) jointTransform(e, i, b);
    V6 vJ = zero6(), aJ = zero6();
    for (int d = 0; d < p.nv; ++d) {
      vJ = add(vJ, scale(cb, cb.input(vIn(p.idx_v + d)), b.S[std::size_t(d)]));
      aJ = add(aJ, scale(cb, cb.input(qddIn(p.idx_v + d)), b.S[std::size_t(d)]));
    }
    V6 v = add(e.motionToChild(b, kin.b[std::size_t(p.parent)].v), vJ);
    if (parentOfSome)
      for (int k = 0; k < 6; ++k) v[std::size_t(k)] = e.keepQ(kV, i, 6, k, v[std::size_t(k)]);
    else
      flatten(cb, v, "v");
    b.v = v;
    const V6 c = crossMotion(cb, v, vJ);
    V6 a = add(add(e.motionToChild(b, p.parent == 0 ? e.rootAcceleration() : out.a[std::size_t(p.parent)]), aJ), c);
    flatten(cb, a, "t");  // used in I a and by the children
    if (parentOfSome)
      for (int k = 0; k < 6; ++k) out.a[std::size_t(i)][std::size_t(k)] = e.putQ(kA, i, 6, k, a[std::size_t(k)]);
    b.IA = constant(e.model().bodies[std::size_t(i)].inertia.matrix());
    V6 h = mul(cb, b.IA, v);
    flatten(cb, h, "h");
    V6 f = add(mul(cb, b.IA, a), crossForce(cb, v, h));
    if (withLambda) addConstraintForces(e, i, f);
    for (int k = 0; k < 6; ++k) out.f[std::size_t(i)][std::size_t(k)] = e.putQ(kF, i, 6, k, f[std::size_t(k)]);
    cb.close();
  }
}

// tau = S^T f, leaves first, each f passed to the parent.
void backward(Emit& e, const Kinematics& kin, Forces& out) {
  const Plan& plan = e.plan;
  const int N = int(plan.bodies.size());
  e.fn.beginPass("backward", "backward: tau = S^T f, f_parent += X^T f");
  for (int i = N - 1; i >= 1; --i) {
    e.fn.boundary(i);
    e.openBody(i, "backward");
    CodeBuilder& cb = e.cb();
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    const V6& f = out.f[std::size_t(i)];
    for (int d = 0; d < p.nv; ++d)
      out.tau[std::size_t(p.idx_v + d)] = e.put(e.member("tau_out", plan.nv, p.idx_v + d, "joint torques (inverse dynamics)"),
                                                dot(cb, kb.S[std::size_t(d)], f));
    if (p.parent > 0) {
      const V6 dp = e.forceToParent(kb, f);
      V6& par = out.f[std::size_t(p.parent)];
      for (int k = 0; k < 6; ++k)
        if (!dp[std::size_t(k)].isZero())
          par[std::size_t(k)] = e.putQ(kF, p.parent, 6, k, par[std::size_t(k)] + dp[std::size_t(k)]);
    }
    cb.close();
  }
}

}  // namespace

std::string emitInverseDynamics(Emit& e, Kinematics kin, const CodeBuilder* afterKinematics, bool nonlinearEffects) {
  const Plan& plan = e.plan;
  const bool withLambda = !nonlinearEffects && plan.nc > 0;
  const int N = int(plan.bodies.size());
  Forces forces{std::vector<V6>(std::size_t(N), zero6()), std::vector<V6>(std::size_t(N), zero6()),
                std::vector<Expr>(std::size_t(plan.nv))};
  // inverse_dynamics sweeps from q, v and qdd itself; nonlinear_effects
  // calls kinematics(q, v, w) and starts from its state.
  if (!nonlinearEffects) {
    kin = Kinematics{};
    kin.b.resize(std::size_t(N));
  }
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().forces = &forces;
  e.fn.beginHost(nonlinearEffects ? "nle" : "rnea", nonlinearEffects ? afterKinematics : nullptr);
  CodeBuilder& host = e.cb();
  if (withLambda) {
    // lambda == nullptr: no constraint forces (a pointer select, no branch in the arithmetic).
    host.line(fmt::format("static constexpr Scalar kNoMultipliers[{}] = {{}};", plan.nc));
    host.line("lambda = lambda != nullptr ? lambda : kNoMultipliers;", {}, {"lambda"});
    // An inactive constraint's rows read the zeros (an index by its flag, no
    // branch): its lambda is never read (docs/algorithms.md §4.4).
    host.line("const MultiplierRows lambda_if[2] = {kNoMultipliers, lambda};", {}, {"lambda"});
    host.line(fmt::format("Scalar lambda_on[{}];", plan.nc));
    for (std::size_t k = 0; k < plan.constraints.size(); ++k) {
      const ConstraintPlan& c = plan.constraints[k];
      for (int r = c.row; r < c.row + c.rows; ++r)
        host.line(fmt::format("lambda_on[{}] = lambda_if[active[{}]][{}];", r, k, r), {}, {"active"});
    }
    host.line("lambda = lambda_on;", {}, {"lambda"});
  }
  if (nonlinearEffects) {
    host.line("kinematics(q, v, w);", {}, {"q", "v", "w"});
    forwardFromKinematics(e, kin, forces);
  } else {
    forwardFused(e, withLambda, kin, forces);
  }
  backward(e, kin, forces);
  e.fn.endPart();
  const char* out = nonlinearEffects ? "h" : "tau";
  CodeBuilder& cb = e.cb();
  for (int j = 0; j < plan.nv; ++j)
    cb.line(fmt::format("{}[{}] = {};", out, j, cb.print(forces.tau[std::size_t(j)])), {forces.tau[std::size_t(j)]}, {out});
  std::string text = nonlinearEffects ? e.fn.endHost({"q", "v", "w", "h"}) : e.fn.endHost({"q", "v", "qdd", "lambda", "w", "tau", "active"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

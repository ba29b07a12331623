// constrainedABA (docs/algorithms.md §4.1): the penalty mu K^T K at the
// constrained bodies, one full sweep (elimination, accelerations, multiplier
// update), then iterations 2..K as reduced sweeps over the support: IA, U, D
// stay, the bias moves linearly in the latest increment. The generic
// counterpart: algorithms/constrained_aba.cpp.
#include <fmt/format.h>

#include <stdexcept>

#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

// lambda += mu (K a - k) for every constraint, keeping the increment for the
// next sweep, and K a - k itself: the rows' residual J qdd + gamma - a* of the
// accelerations just computed (residual(w) reads the last one). Both times the
// constraint's activity factor: an inactive constraint's residual rows, its
// increments and so its multipliers stay exactly 0 (docs/algorithms.md §4.4).
void updateMultipliers(Emit& e, const Kinematics& kin, const Motion& motion, Multipliers& mult) {
  e.fn.boundary("");
  CodeBuilder& cb = e.cb();
  cb.open("{", {"multiplier update: dlambda = mu (K a - k), lambda += dlambda (0 for an inactive constraint)"});
  for (std::size_t k = 0; k < e.sys.constraints.size(); ++k) {
    const Constraint& c = e.sys.constraints[k];
    const std::vector<Expr> Ka = e.constraintRows(int(k), c.body == 0 ? e.rootAcceleration() : motion.a[std::size_t(c.body)]);
    for (int j = 0; j < c.rows(); ++j) {
      const int row = c.row + j;
      const Expr mu = cb.input("mu");  // before the difference's temporary: see mulAdd in symbolic.cpp
      const Expr on = activeFactor(e, int(k));
      const Expr res = cb.store(residualMember(e, row), cb.mul(on, cb.flat(Ka[std::size_t(j)] - kin.k[k][std::size_t(j)])));
      const Expr dl = cb.mul(mu, res);
      mult.dlambda[std::size_t(row)] = e.put(e.member("dlambda", e.plan.nc, row, "latest multiplier increment"), dl);
      mult.lambda[std::size_t(row)] = e.put(e.lambdaMember(row), mult.lambda[std::size_t(row)] + mult.dlambda[std::size_t(row)]);
    }
  }
  cb.close();
}

// One reduced sweep, leaves first: u_i -= S^T dp_i, and dp passes to the parent.
void reducedSweep(Emit& e, const Kinematics& kin, const Multipliers& mult, Articulated& art, Increments& inc) {
  for (int i : e.plan.support) inc.dp[std::size_t(i)] = zero6();
  for (auto it = e.plan.support.rbegin(); it != e.plan.support.rend(); ++it) {
    const int i = *it;
    e.fn.boundary(i);
    CodeBuilder& cb = e.cb();
    Articulated::Body& b = art.b[std::size_t(i)];
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const BodyPlan& p = e.bp(i);
    e.openBody(i, "reduced sweep:");
    V6 dp = inc.dp[std::size_t(i)];
    for (int k : p.constraints) {
      const Constraint& c = e.sys.constraints[std::size_t(k)];
      const Mat6 X = c.placement.motionMatrixInv();
      for (int r = 0; r < 6; ++r)
        for (int j = 0; j < c.rows(); ++j) dp[std::size_t(r)] += X(j, r) * mult.dlambda[std::size_t(c.row + j)];
    }
    if (p.jointClass == JointClass::FreeFlyer) {
      for (int d = 0; d < 6; ++d)
        b.u[std::size_t(d)] = cb.store(e.member(kUu, i, 6, d), b.u[std::size_t(d)] - dp[std::size_t(d)]);
    } else if (p.jointClass == JointClass::Planar) {
      // u -= S^T dp (S picks sel); below a moving parent dp + U D^-1 (-S^T dp) passes on.
      const std::vector<int> sel = pickedComponents(p.jointClass);
      const int n = int(sel.size());
      std::vector<Expr> du(static_cast<std::size_t>(n));
      for (int d = 0; d < n; ++d) {
        du[std::size_t(d)] = -dp[std::size_t(sel[std::size_t(d)])];
        b.u[std::size_t(d)] = cb.store(e.member(kUu, i, n, d), b.u[std::size_t(d)] + du[std::size_t(d)]);
      }
      if (p.parent != 0) {
        const std::vector<Expr> x = choleskySolve(cb, b.L, b.Linv, du);
        V6 t;
        for (int r = 0; r < 6; ++r) {
          t[std::size_t(r)] = dp[std::size_t(r)];
          for (int d = 0; d < n; ++d) t[std::size_t(r)] += cb.mul(b.U[std::size_t(d)][std::size_t(r)], x[std::size_t(d)]);
        }
        const V6 f = e.forceToParent(kb, t);
        V6& par = inc.dp[std::size_t(p.parent)];
        for (int r = 0; r < 6; ++r)
          if (!f[std::size_t(r)].isZero()) par[std::size_t(r)] = e.putQ(kDP, p.parent, 6, r, par[std::size_t(r)] + f[std::size_t(r)]);
      }
    } else {
      const Expr du = cb.flat(-dot(cb, kb.S[0], dp), "du");
      b.u[0] = cb.store(e.member(kUu, i, 1, 0), b.u[0] + du);
      if (p.parent != 0) {
        const Expr x = cb.flat(cb.mul(b.Dinv, du), "x");
        V6 t;
        for (int r = 0; r < 6; ++r) t[std::size_t(r)] = dp[std::size_t(r)] + cb.mul(b.U[0][std::size_t(r)], x);
        // S^T t = S^T dp + D D^-1 du = 0: along an axis-aligned S the component is
        // exactly 0 (the products cancelled only to round-off), and so are its moves.
        if (const int along = axisComponent(p); along >= 0) t[std::size_t(along)] = Expr();
        const V6 f = e.forceToParent(kb, t);
        V6& par = inc.dp[std::size_t(p.parent)];
        for (int r = 0; r < 6; ++r)
          if (!f[std::size_t(r)].isZero()) par[std::size_t(r)] = e.putQ(kDP, p.parent, 6, r, par[std::size_t(r)] + f[std::size_t(r)]);
      }
    }
    cb.close();
  }
}

// pA_i += K^T lambda0 for the constraints on body i: the warm start's force
// (the force on the robot is -K^T lambda), so the first sweep solves for
// lambda0 + mu (K a - k) as the generic constrainedAba does.
void warmStartForce(Emit& e, int i, const Multipliers& mult, Articulated& art) {
  V6& pA = art.b[std::size_t(i)].pA;
  for (int k : e.bp(i).constraints) {
    const Constraint& c = e.sys.constraints[std::size_t(k)];
    const Mat6 X = c.placement.motionMatrixInv();
    for (int r = 0; r < 6; ++r)
      for (int j = 0; j < c.rows(); ++j) pA[std::size_t(r)] += X(j, r) * mult.lambda[std::size_t(c.row + j)];
  }
}

// What the iteration loop carries: the same expressions at its start and end.
std::string fingerprint(const CodeBuilder& cb, const std::vector<int>& bodies, const Motion& motion, const Articulated& art,
                        const Multipliers& mult) {
  std::string f;
  auto add = [&](const Expr& x) { f += cb.describe(x) + ";"; };
  for (int i : bodies) {
    for (const Expr& x : motion.a[std::size_t(i)]) add(x);
    for (const Expr& x : art.b[std::size_t(i)].u) add(x);
  }
  for (const Expr& x : mult.lambda) add(x);
  for (const Expr& x : mult.dlambda) add(x);
  return f;
}

}  // namespace

std::string residualMember(Emit& e, int row) {
  return e.member("residual", e.plan.nc, row, "rows of J qdd + gamma - a* of the last solve (residual(w))");
}

std::string activeMember(Emit& e, int k) {
  return e.member("active", int(e.plan.constraints.size()), k, "the schedule of the last call (Settings::active) as 0/1 factors");
}

void storeActiveFactors(Emit& e, const std::string& flags) {
  CodeBuilder& cb = e.cb();
  for (std::size_t k = 0; k < e.plan.constraints.size(); ++k) {
    const std::string m = activeMember(e, int(k));
    cb.line(fmt::format("{} = Scalar({}[{}]);", m, flags, k), {}, {flags.substr(0, flags.find('.')), m});
  }
}

Expr activeFactor(Emit& e, int k) { return e.cb().member(activeMember(e, k)); }

int rowConstraint(const Plan& plan, int row) {
  for (std::size_t k = 0; k < plan.constraints.size(); ++k) {
    const ConstraintPlan& c = plan.constraints[k];
    if (row >= c.row && row < c.row + c.rows) return int(k);
  }
  throw std::logic_error("emitter: a row outside the layout");
}

Expr activeRowFactor(Emit& e, int row) { return activeFactor(e, rowConstraint(e.plan, row)); }

// In the host, before the first sweep: lambda = lambda0 (s.lambda0, or zeros
// when it is null: the runtime's pointer select); an inactive constraint's
// rows read the zeros instead (an index by its flag, no branch), so its
// lambda0 is never read, whatever it holds.
void startMultipliers(Emit& e, Multipliers& mult) {
  if (e.plan.nc == 0) return;
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  cb.comment("---- warm start: lambda = s.lambda0, or 0 when it is null or the constraint inactive");
  cb.line("const auto lambda0 = proxgen_rt::initial_multipliers<nc>(s.lambda0);", {}, {"s"});
  cb.line("const MultiplierRows lambda0_if[2] = {proxgen_rt::initial_multipliers<nc, Scalar>(nullptr), lambda0};");
  for (std::size_t k = 0; k < e.plan.constraints.size(); ++k) {
    const ConstraintPlan& c = e.plan.constraints[k];
    for (int r = c.row; r < c.row + c.rows; ++r)
      mult.lambda[std::size_t(r)] = cb.store(e.lambdaMember(r), cb.input(fmt::format("lambda0_if[s.active[{}]][{}]", k, r)));
  }
}

// qdd and lambda out of the workspace.
void copyOut(Emit& e, const Motion& motion, const Multipliers& mult) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  for (int j = 0; j < e.plan.nv; ++j)
    cb.line(fmt::format("qdd[{}] = {};", j, cb.print(motion.qdd[std::size_t(j)])), {motion.qdd[std::size_t(j)]}, {"qdd"});
  for (int r = 0; r < e.plan.nc; ++r)
    cb.line(fmt::format("lambda[{}] = {};", r, cb.print(mult.lambda[std::size_t(r)])), {mult.lambda[std::size_t(r)]},
            {"lambda"});
}

std::string emitConstrainedAba(Emit& e, Kinematics kin, Articulated art, const CodeBuilder* from) {
  const Plan& plan = e.plan;
  Motion motion{std::vector<V6>(art.b.size(), zero6()), std::vector<Expr>(std::size_t(plan.nv))};
  Multipliers mult{std::vector<Expr>(std::size_t(plan.nc)), std::vector<Expr>(std::size_t(plan.nc))};
  Increments inc{std::vector<V6>(art.b.size(), zero6())};
  e.fn.live() = Live{&kin, &art, &motion, &inc, nullptr, &mult, nullptr};
  e.fn.beginHost("caba", from);
  e.fn.setHostMu(e.cb().define("mu", "s.mu * Scalar(s.iterations > 0)", {}, {"s"}));
  storeActiveFactors(e, "s.active");
  e.cb().line("kinematics(q, v, w);", {}, {"q", "v", "w"});
  if (!plan.offSupport.empty()) e.cb().line("eliminate_free_bodies(tau, w);", {}, {"tau", "w"});
  startMultipliers(e, mult);
  e.fn.beginPass("backward", "backward: eliminate the support, the penalty mu K^T K at the constrained bodies");
  for (auto it = plan.support.rbegin(); it != plan.support.rend(); ++it) {
    e.fn.boundary(*it);
    e.openBody(*it, "eliminate (penalty at the constraints):");
    warmStartForce(e, *it, mult, art);
    eliminateBody(e, kin, *it, &kin.k, art);
    e.cb().close();
  }
  e.fn.beginPass("forward", "forward: accelerations of the support");
  accelerateSupport(e, kin, art, motion);
  if (plan.nc > 0) {
    e.fn.beginPass("multipliers", "multipliers: dlambda = mu (K a - k), lambda = lambda0 + dlambda");
    updateMultipliers(e, kin, motion, mult);
    e.fn.endPart();
    const std::string before = fingerprint(e.cb(), plan.support, motion, art, mult);
    e.cb().open("for (int k = 2; k <= s.iterations; ++k) {",
                {"Iterations 2..K: reduced sweeps over the support (K = 0 or 1: no pass)."}, {"s"});
    e.fn.beginPass("reduced", "reduced sweep: u -= S^T dp, dp passes to the parent");
    reducedSweep(e, kin, mult, art, inc);
    e.fn.beginPass("reforward", "forward: accelerations of the support");
    accelerateSupport(e, kin, art, motion);
    e.fn.beginPass("update", "multipliers: dlambda = mu (K a - k), lambda += dlambda");
    updateMultipliers(e, kin, motion, mult);
    e.fn.endPart();
    if (fingerprint(e.cb(), plan.support, motion, art, mult) != before)
      throw std::logic_error("emitter: the iteration loop does not carry its state consistently");
    e.cb().close();
  }
  callAccelerateFree(e, kin, art, motion);
  copyOut(e, motion, mult);
  std::string text = e.fn.endHost({"q", "v", "tau", "s", "w", "qdd", "lambda"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

// The constraint frames, generated (docs/dynamics.md): constraint_placements,
// constraint_jacobian and constraint_drift, in the rows the solvers hold
// (6d weld: [linear; angular] of frame C in C; 3d point: the linear rows of C),
// so that J qdd + gamma is the acceleration the solvers drive to a*. The
// functions of q alone start from constraint_joints(q, w), the joint
// transforms (the kinematics pass's first step) printed once for them and the
// Delassus functions; constraint_drift calls kinematics(q, v, w) itself. The
// generic counterpart: algorithms/constraint_kinematics.cpp.
#include <fmt/format.h>

#include "emit/identifiers.hpp"
#include "emit/passes.hpp"

namespace proxgen::emit {
namespace {

constexpr Quantity kJK{"JK", "constraint row directions of the subtree rows (Jacobian), 6 x m"};

// The part of a host that reads the helper's state: kin moves in from `from`.
void beginFrom(Emit& e, const std::string& host, const CodeBuilder* from, Kinematics& kin, ConstraintOutputs& out,
               ProxRows* rows = nullptr) {
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.live().rows = rows;
  e.fn.live().cons = &out;
  e.fn.beginHost(host, from);
}

std::string constraintComment(const Emit& e, int k) {
  const ConstraintPlan& c = e.plan.constraints[std::size_t(k)];
  return fmt::format("constraint '{}' ({}) on link '{}': rows {}..{}", escapeComment(c.name), c.weld ? "6d" : "3d",
                     escapeComment(c.link), c.row, c.row + c.rows - 1);
}

}  // namespace

void copyOutput(Emit& e, const std::string& name, const std::vector<Expr>& out) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  for (std::size_t k = 0; k < out.size(); ++k)
    cb.line(fmt::format("{}[{}] = {};", name, k, cb.print(out[k])), {out[k]}, {name});
}

void scheduleOutput(Emit& e, std::vector<Expr>& out, int cols, bool columnsToo) {
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (out[k].isZero()) continue;
    const int r = int(k) / cols, c = int(k) % cols;
    Expr f = activeRowFactor(e, r);
    if (columnsToo && rowConstraint(e.plan, c) != rowConstraint(e.plan, r)) f = cb.mul(f, activeRowFactor(e, c));
    out[k] = cb.mul(f, cb.flat(out[k]));
  }
}

ConstraintJoints emitConstraintJoints(Emit& e, bool all) {
  ConstraintJoints j;
  const Model& m = e.model();
  j.kin.b.resize(std::size_t(m.numBodies()));
  e.fn.live() = Live{};
  e.fn.live().kin = &j.kin;
  e.fn.beginHost("joints", nullptr);
  sincosRuns(e, !all);
  for (int i = 1; i < m.numBodies(); ++i) {
    if (!all && !e.bp(i).onSupport) continue;
    e.fn.boundary(i);
    e.openBody(i, "joint transform:");
    jointTransform(e, i, j.kin.b[std::size_t(i)]);
    j.kin.b[std::size_t(i)].IA = constant(m.bodies[std::size_t(i)].inertia.matrix());
    e.cb().close();
  }
  j.text = e.fn.endHost({"q", "w"});
  j.host = e.fn.lastHost();
  e.fn.live() = Live{};
  return j;
}

std::string emitConstraintPlacements(Emit& e, const ConstraintJoints& joints) {
  Kinematics kin = joints.kin;
  ConstraintOutputs out;
  out.out.assign(12 * e.sys.constraints.size(), Expr());
  beginFrom(e, "placements", joints.host, kin, out);
  e.cb().line("constraint_joints(q, w);", {}, {"q", "w"});
  kin.b[0].oM = constant(SE3::Identity());
  // Per constraint: R (row-major) then p of oMc = oM_i * placement.
  auto frame = [&](int k, const XSym& oMi) {
    const Constraint& c = e.sys.constraints[std::size_t(k)];
    const XSym oMc = compose(e.cb(), oMi, constant(c.placement));
    for (int r = 0; r < 12; ++r) {
      const Expr x = r < 9 ? oMc.R[std::size_t(r)] : oMc.p[std::size_t(r - 9)];
      const int slot = 12 * k + r;
      out.out[std::size_t(slot)] =
          e.put(e.member("oMc", 12 * int(e.sys.constraints.size()), slot, "constraint frame placements"), e.cb().flat(x));
    }
  };
  e.fn.beginPass("world", "world placements of the support bodies, then of the constraint frames");
  if (!e.bp(0).constraints.empty()) {
    e.fn.boundary("world");
    e.cb().open("{", {"constraints on the world"});
    for (int k : e.bp(0).constraints) frame(k, kin.b[0].oM);
    e.cb().close();
  }
  for (int i : e.plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "world placement:");
    Kinematics::Body& b = kin.b[std::size_t(i)];
    const XSym M = compose(e.cb(), compose(e.cb(), kin.b[std::size_t(e.bp(i).parent)].oM, b.XT), b.XJ);
    for (int k = 0; k < 9; ++k)
      b.oM.R[std::size_t(k)] = e.keepQ(kOR, i, 3, 3, k / 3, k % 3, e.cb().flat(M.R[std::size_t(k)]));
    for (int k = 0; k < 3; ++k) b.oM.p[std::size_t(k)] = e.keepQ(kOP, i, 3, k, e.cb().flat(M.p[std::size_t(k)]));
    for (int k : e.bp(i).constraints) {
      e.cb().comment(constraintComment(e, k));
      frame(k, b.oM);
    }
    e.cb().close();
  }
  copyOutput(e, "X", out.out);
  std::string text = e.fn.endHost({"q", "w", "X"});
  e.fn.live() = Live{};
  return text;
}

std::string emitConstraintJacobian(Emit& e, const ConstraintJoints& joints) {
  const Plan& plan = e.plan;
  Kinematics kin = joints.kin;
  ConstraintOutputs out;
  out.out.assign(std::size_t(plan.nc * plan.nv), Expr());
  ProxRows rows;
  rows.b.resize(kin.b.size());
  // KA = K^T: the own rows' force directions, then each child's (below).
  for (int i : plan.support) initOwnRows(e, i, rows);
  beginFrom(e, "jacobian", joints.host, kin, out, &rows);
  storeActiveFactors(e, "active");
  e.cb().line("constraint_joints(q, w);", {}, {"q", "w"});
  // J(row, v_j) = S_j^T X_j^T ... X_i^T K_row^T: each row's direction carried
  // up its constraint's path as a force, read by every joint on the way.
  e.fn.beginPass("rows", "rows: K^T carried up the support as forces, J = S^T K^T at each joint");
  for (auto it = plan.support.rbegin(); it != plan.support.rend(); ++it) {
    const int i = *it;
    const BodyPlan& p = e.bp(i);
    e.fn.boundary(i);
    e.openBody(i, "Jacobian columns of the joint:");
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    ProxRows::Body& b = rows.b[std::size_t(i)];
    for (int c = 0; c < p.m(); ++c) {
      const int row = p.subtreeRows[std::size_t(c)];
      for (int d = 0; d < p.nv; ++d) {
        const std::size_t slot = std::size_t(row * plan.nv + p.idx_v + d);
        out.out[slot] = e.put(e.ws.member("Jc", plan.nc, plan.nv, row, p.idx_v + d, "constraint Jacobian (nc x nv)"),
                              dot(e.cb(), kb.S[std::size_t(d)], b.KA[std::size_t(c)]));
      }
      if (p.parent == 0) continue;
      const int mp = e.bp(p.parent).m(), col = p.offsetInParent + c;
      const V6 f = e.forceToParent(kb, b.KA[std::size_t(c)]);
      for (int r = 0; r < 6; ++r)
        rows.b[std::size_t(p.parent)].KA[std::size_t(col)][std::size_t(r)] =
            e.put(e.member(kJK, p.parent, 6, mp, r, col), f[std::size_t(r)]);
    }
    e.cb().close();
  }
  scheduleOutput(e, out.out, plan.nv, false);  // an inactive constraint's rows: 0
  copyOutput(e, "J", out.out);
  std::string text = e.fn.endHost({"q", "w", "J", "active"});
  e.fn.live() = Live{};
  return text;
}

std::string emitConstraintDrift(Emit& e, const Kinematics& kinIn, const CodeBuilder* afterKinematics) {
  const Plan& plan = e.plan;
  Kinematics kin = kinIn;
  ConstraintOutputs out;
  out.out.assign(std::size_t(plan.nc), Expr());
  Motion motion{std::vector<V6>(kin.b.size(), zero6()), {}};
  beginFrom(e, "drift", afterKinematics, kin, out);
  e.fn.live().motion = &motion;
  storeActiveFactors(e, "active");
  e.cb().line("kinematics(q, v, w);", {}, {"q", "v", "w"});
  // gamma = the rows' acceleration at qdd = 0 without gravity: a_i = X_i a_p + c_i
  // from a_0 = 0, then K X_C a_i (+ w_C x v_C for a point, its classical acceleration).
  e.fn.beginPass("accel", "accelerations at qdd = 0 without gravity, and the rows' gamma");
  for (int i : plan.support) {
    e.fn.boundary(i);
    e.openBody(i, "acceleration at qdd = 0:");
    const Kinematics::Body& kb = kin.b[std::size_t(i)];
    const int p = e.bp(i).parent;
    const V6 a = add(e.motionToChild(kb, p == 0 ? zero6() : motion.a[std::size_t(p)]), kb.c);
    for (int r = 0; r < 6; ++r) motion.a[std::size_t(i)][std::size_t(r)] = e.putQ(kA, i, 6, r, a[std::size_t(r)]);
    for (int k : e.bp(i).constraints) {
      const Constraint& c = e.sys.constraints[std::size_t(k)];
      e.cb().comment(constraintComment(e, k));
      std::vector<Expr> g = e.constraintRows(k, motion.a[std::size_t(i)]);
      if (c.type != ConstraintType::Weld6D) {
        const V6 vC = actInvMotion(e.cb(), constant(c.placement), kb.v);
        const V3 wxv = cross(e.cb(), ang(vC), lin(vC));
        for (int j = 0; j < 3; ++j) g[std::size_t(j)] += wxv[std::size_t(j)];
      }
      for (int j = 0; j < c.rows(); ++j)
        out.out[std::size_t(c.row + j)] =
            e.put(e.member("gamma", plan.nc, c.row + j, "constraint drift (layout order)"), g[std::size_t(j)]);
    }
    e.cb().close();
  }
  scheduleOutput(e, out.out, 1, false);  // an inactive constraint's rows: 0
  copyOutput(e, "gamma", out.out);
  std::string text = e.fn.endHost({"q", "v", "w", "gamma", "active"});
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

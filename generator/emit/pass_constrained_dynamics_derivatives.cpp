// constrained_dynamics_derivatives (docs/derivatives.md section 3): the
// derivatives of the solution prox_pv converges to, by the implicit function
// theorem on M qdd + h + J^T lambda = tau, J qdd + gamma = a*:
//   M X + J^T L = R1 = [-dtau/dq, -dtau/dv, I],   J X = R2 = d a*/dx - d alpha/dx  (x = q, v; 0 for tau),
// L by the Settings' K proximal steps (G + I/mu) L+ = C + L/mu from 0,
// C = J M^-1 R1 - R2, and X = M^-1 (R1 - J^T L), evaluated as
// X_tau = P = M^-1 - W Lt, X_x = P R1_x + Lt^T R2_x, L_x = Lt R1_x - S_K R2_x
// (W = M^-1 J^T, Lt = S_K W^T: docs/derivatives.md section 5). The host calls
// prox_pv, mass_matrix_inverse's passes on prox_pv's factors and
// inverse_dynamics_derivatives' sweep (held with it); the constraint rows (J,
// R2) are formed from the sweep's world-frame vectors of the path's dofs, a
// loop per run of columns of one shape; the matrix algebra (O((nv + nc)
// (nnz(dtau) + nnz(R2)) + nv^2 nc / 2 + nc^2 nv), plus about 2 nc^3 / 3 + (K - 1)
// nc^3 / 2 for the proximal operator S_K) is fixed-bound loops printed once by
// assemble.cpp, the products with dtau, J and R2 over their nonzero patterns
// (constant tables of column ranges). The generic counterpart:
// algorithms/derivatives.cpp (constrainedDynamicsDerivatives, constraintRowTangents).
#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <set>

#include "emit/identifiers.hpp"
#include "emit/passes.hpp"
#include "model/error.hpp"

namespace proxgen::emit {
namespace {

std::string rowsComment(const Emit& e, int k) {
  const ConstraintPlan& c = e.plan.constraints[std::size_t(k)];
  return fmt::format("constraint '{}' ({}) on link '{}': rows {}..{}", escapeComment(c.name), c.weld ? "6d" : "3d",
                     escapeComment(c.link), c.row, c.row + c.rows - 1);
}

struct RowMembers {
  std::string J;   // nc x nv
  std::string R2;  // nc x 2 nv: R2's q and v columns side by side
  std::set<std::pair<int, int>> Jnz;     // J's entries written (row, column): its pattern
  std::set<std::pair<int, int>> R2nz[2];  // R2_q's and R2_v's entries written
};

// What every column of one constraint's rows reads, stored once (a slot per
// value: a constant, or the member it went to).
struct RowFrame {
  std::vector<TangentSlot> R, p, V, err, jri;  // R_C (row-major), p_C, sh(ov_b) (3d), e in world axes (3d, kp), Jr(e)^-1 (6d, kp)
};

// x into entries offset.. of the member array `base` (of `size`).
std::vector<TangentSlot> keepSlots(Emit& e, const std::string& base, int offset, int size, const std::vector<Expr>& x) {
  return slotsOf(e, x, [&](int k) {
    return e.ws.member(base, size, offset + k, "the constraint frame's values the rows read (constrained_dynamics_derivatives)");
  });
}

V3 v3(const std::vector<Expr>& x, std::size_t from = 0) { return {x[from], x[from + 1], x[from + 2]}; }
V3 plus(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 minus(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 times(double k, const V3& a) { return {k * a[0], k * a[1], k * a[2]}; }

// The frame C = oM_b P in world axes from the sweep's placement of the body:
// R_C, p_C, the body's velocity moved to C's origin (world axes), the 3d
// position error in world axes (e = R_C^T (p_C - p_T), so R_C e = p_C - p_T),
// and for a 6d weld with kp, Jr(e)^-1 of its error e = log6(T^-1 oMc) (as the
// kinematics pass computes e, then the helper, into a member).
RowFrame constraintFrame(Emit& e, int k, const BodyTangents::Body& tb) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const std::string id = e.plan.constraints[std::size_t(k)].ident;
  const bool weld = c.type == ConstraintType::Weld6D;
  CodeBuilder& cb = e.cb();
  XSym oMb;
  for (std::size_t j = 0; j < 9; ++j) oMb.R[j] = load(cb, tb.R[j]);
  for (std::size_t j = 0; j < 3; ++j) oMb.p[j] = load(cb, tb.p[j]);
  const XSym oMc = compose(cb, oMb, constant(c.placement));
  const std::string base = "cdd_frame_" + id;
  const int size = 9 + 3 + (weld ? 0 : 6 + 3);
  RowFrame f;
  f.R = keepSlots(e, base, 0, size, std::vector<Expr>(oMc.R.begin(), oMc.R.end()));
  f.p = keepSlots(e, base, 9, size, std::vector<Expr>(oMc.p.begin(), oMc.p.end()));
  if (!weld) {
    const V6 ov = load(cb, tb.ov);
    const V3 Vl = plus(lin(ov), cross(cb, ang(ov), oMc.p));
    f.V = keepSlots(e, base, 12, size, {Vl[0], Vl[1], Vl[2], ov[3], ov[4], ov[5]});
    if (c.kp != 0) {
      std::vector<Expr> d;
      for (int j = 0; j < 3; ++j) d.push_back(oMc.p[std::size_t(j)] - c.target.p[j]);
      f.err = keepSlots(e, base, 18, size, d);
    }
  } else if (c.kp != 0) {
    weldError(cb, oMc, c, "jr", id);
    const std::string jri = "cdd_jri_" + id;
    e.ws.member(jri, 36, 0, "Jr(e)^-1 of the weld's error (constrained_dynamics_derivatives)");
    OpCount ops;
    ops.once = se3RightJacobianInverseOps();
    cb.line(fmt::format("se3_right_jacobian_inverse(jre_{}, w.{});", id, jri), {}, {"w"}, ops);
    f.jri.resize(36);
    for (int j = 0; j < 36; ++j) f.jri[std::size_t(j)].name = fmt::format("w.{}[{}]", jri, j);
  }
  return f;
}

// One column of one constraint's rows: J, and R2 = d a*/dx - d alpha/dx for
// x = q, v at fixed qdd (alpha: the frame's spatial acceleration in C, 6d; the
// classical acceleration a_lin + w x v_lin of its origin, 3d), from the
// sweep's world-frame vectors of the column's dof (docs/derivatives.md
// sections 2b and 5): moving q_j moves C with the joint's subtree, so in C's
// coordinates dv_C = R_C^T sh(-u), da_C = R_C^T sh(c - u x ov_b + s x oa_0) (the
// true acceleration: the gravity-shifted one less the gravity's tangent), and
// along qd_j dv_C = R_C^T sh(s), da_C = R_C^T sh(s x ov_b + w), where sh(m) =
// [m_lin + m_ang x p_C; m_ang] moves a world-frame motion to C's origin. The
// cross products of the 3d rows commute with the rotation, so each row is
// formed in world axes and turned into C once. A dof whose joint hangs from the
// world (`rooted`: u = s x ov_0 = 0, c = -s x oa_0) moves the whole robot
// rigidly: nothing moves relative to the joint's frame, so dv_C and the true
// da_C along it are zero, exactly (the terms above cancel). Entries are
// multiplied by the constraint's schedule factor; `store(which, row, entry)`
// for J (0), R2_q (1) and R2_v (2), exact zeros included (it skips them).
void constraintColumn(Emit& e, int k, const RowFrame& frame, const std::vector<Expr>& in, bool rooted,
                      const std::function<void(int, int, const Expr&)>& store) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const bool weld = c.type == ConstraintType::Weld6D;
  CodeBuilder& cb = e.cb();
  const Expr f = activeFactor(e, k);
  const std::vector<Expr> Rv = load(cb, frame.R), pv = load(cb, frame.p);
  M3 R;
  std::copy(Rv.begin(), Rv.end(), R.begin());
  const V3 p = v3(pv);
  const V6 s = toV6(in, 0), u = toV6(in, 6), cq = toV6(in, 12), w = toV6(in, 18);
  const V6 ovb = toV6(in, 24);
  const V6 a0 = e.rootAcceleration();
  const auto shifted = [&](const V6& m) { return plus(lin(m), cross(cb, ang(m), p)); };
  // The four tangents in world axes at C's origin (linear parts; angular parts are the vectors').
  const V3 Jl = shifted(s), Ja = ang(s);
  const V3 vql = rooted ? zero3() : times(-1.0, shifted(u)), vqa = rooted ? zero3() : times(-1.0, ang(u));
  V6 mq = zero6();
  if (!rooted) {
    mq = sub(cq, crossMotion(cb, u, ovb));
    const V3 g = cross(cb, ang(s), lin(a0));
    for (std::size_t j = 0; j < 3; ++j) mq[j] += g[j];
  }
  const V3 aql = shifted(mq), aqa = ang(mq);
  const V6 mv = add(crossMotion(cb, s, ovb), w);
  const V3 avl = shifted(mv), ava = ang(mv);
  std::vector<Expr> J, Rq, Rv2;
  if (!weld) {
    const std::vector<Expr> Vv = load(cb, frame.V);
    const V3 Vl = v3(Vv), Va = v3(Vv, 3);
    // d(w x v) = dw x v + w x dv
    const V3 Aq = plus(aql, plus(cross(cb, vqa, Vl), cross(cb, Va, vql)));
    const V3 Av = plus(avl, plus(cross(cb, Ja, Vl), cross(cb, Va, Jl)));
    V3 Sq = times(-c.kd, vql);
    if (c.kp != 0) {  // de = J6_lin dq + e x J6_ang dq
      const V3 ex = cross(cb, v3(load(cb, frame.err)), Ja);
      Sq = minus(Sq, times(c.kp, plus(Jl, ex)));
    }
    const V3 Sv = times(-c.kd, Jl);
    const V3 j3 = rotateT(cb, R, Jl), q3 = rotateT(cb, R, minus(Sq, Aq)), v3r = rotateT(cb, R, minus(Sv, Av));
    J.assign(j3.begin(), j3.end());
    Rq.assign(q3.begin(), q3.end());
    Rv2.assign(v3r.begin(), v3r.end());
  } else {
    const V3 Jcl = rotateT(cb, R, Jl), Jca = rotateT(cb, R, Ja);
    J = {Jcl[0], Jcl[1], Jcl[2], Jca[0], Jca[1], Jca[2]};
    const V3 ql = rotateT(cb, R, minus(times(-c.kd, vql), aql)), qa = rotateT(cb, R, minus(times(-c.kd, vqa), aqa));
    const V3 vl = rotateT(cb, R, minus(times(-c.kd, Jl), avl)), va = rotateT(cb, R, minus(times(-c.kd, Ja), ava));
    Rq = {ql[0], ql[1], ql[2], qa[0], qa[1], qa[2]};
    Rv2 = {vl[0], vl[1], vl[2], va[0], va[1], va[2]};
    if (c.kp != 0) {  // de = Jr(e)^-1 J6 dq
      const std::vector<Expr> jri = load(cb, frame.jri);
      std::vector<Expr> J6f;
      for (const Expr& x : J) J6f.push_back(cb.flat(x));
      J = J6f;
      for (std::size_t j = 0; j < 6; ++j) {
        Expr sum;
        for (std::size_t l = 0; l < 6; ++l)
          if (!J6f[l].isZero()) sum += cb.mul(jri[6 * j + l], J6f[l]);
        Rq[j] -= c.kp * sum;
      }
    }
  }
  for (int j = 0; j < c.rows(); ++j) {
    store(0, j, cb.mul(f, cb.flat(J[std::size_t(j)])));
    store(1, j, cb.mul(f, cb.flat(Rq[std::size_t(j)])));
    store(2, j, cb.mul(f, cb.flat(Rv2[std::size_t(j)])));
  }
}

// One constraint's rows over the columns of its body's path (ascending), a loop
// per run of columns whose inputs have one shape (column_loops.cpp).
void constraintRows(Emit& e, int k, const BodyTangents& t, RowMembers& m) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const ConstraintPlan& cp = e.plan.constraints[std::size_t(k)];
  const int i = c.body, nv = e.plan.nv, nc = e.plan.nc;
  e.fn.boundary(i);
  e.openBody(i, "constraint rows:");
  e.cb().comment(rowsComment(e, k));
  const RowFrame frame = constraintFrame(e, k, t.body[std::size_t(i)]);
  e.cb().close();
  std::vector<int> cols;
  std::set<int> rooted;  // the dofs of a joint that hangs from the world
  for (int j = i; j > 0; j = e.bp(j).parent)
    for (int d = 0; d < e.bp(j).nv; ++d) {
      cols.push_back(e.bp(j).idx_v + d);
      if (e.bp(j).parent == 0) rooted.insert(e.bp(j).idx_v + d);
    }
  std::sort(cols.begin(), cols.end());
  const auto inputs = [&](int col) {
    std::vector<Expr> in;
    for (const TangentCol& x : t.dof[std::size_t(col)])
      for (const Expr& y : load(e.cb(), x)) in.push_back(y);
    return in;
  };
  const auto sameShape = [&](int a, int a0) {
    return rooted.count(a) == rooted.count(a0) && oneShape(e.cb(), inputs, a, a0);
  };
  for (const auto& run : columnRuns(cols, sameShape)) {
    const int k0 = run.first, len = run.second;  // named: lambdas capture them (C++17)
    openColumns(e, cp.ident, k0, len, fmt::format("constraint '{}' rows,", escapeComment(c.name)));
    CodeBuilder& cb = e.cb();  // after openColumns: it may have started a new part
    std::vector<Expr> in = len > 1 ? loopReads(cb, inputs(k0)) : inputs(k0);
    for (const Expr& x : load(cb, t.body[std::size_t(i)].ov)) in.push_back(x);
    const auto store = [&](int which, int j, const Expr& x) {
      if (x.isZero()) return;  // the host zeroed the arrays; not in the pattern
      const int row = c.row + j;
      const std::string& base = which == 0 ? m.J : m.R2;
      const int size = which == 0 ? nc * nv : 2 * nc * nv;
      const int idx = which == 0 ? row * nv + k0 : row * 2 * nv + (which == 2 ? nv : 0) + k0;
      const char* what = "constrained_dynamics_derivatives";
      cb.store(len > 1 ? e.ws.loopSlot(base, size, idx, what) : e.ws.member(base, size, idx, what), x);
      for (int col = k0; col < k0 + len; ++col) {
        if (which == 0) m.Jnz.insert({row, col});
        else m.R2nz[which - 1].insert({row, col});
      }
    };
    constraintColumn(e, k, frame, in, rooted.count(k0) > 0, store);
    cb.close();
  }
}
}  // namespace

// The helpers' arithmetic (assemble.cpp prints them; counted as they are written).
Ops denseProductAddOps(int n, int m, int p) { return denseProductOps(n, m, p); }  // the same loops, into C

Ops denseCholeskyOps(int n) {
  Ops o;
  for (long j = 0; j < n; ++j) {
    o.mul += j + (n - 1 - j) * (j + 1);
    o.add += j + (n - 1 - j) * j;
  }
  o.add += n;  // the shift
  o.sqrt = n;
  o.div = n;
  return o;
}

// proximal_inverse: X's row i (i + 1 columns, i terms and the scaling), A's row i
// (n - i columns, n - i terms); the mirror copies.
Ops proximalInverseOps(int n) {
  Ops o;
  for (long i = 0; i < n; ++i) {
    o.mul += i + i * (i + 1) + (i + 1);
    o.add += i * (i + 1);
    o.mul += (n - i) * (n - i);
    o.add += (n - i) * (n - i);
  }
  return o;
}

// proximal_power: row i of A S / mu over n - i columns (n scalings of A's row),
// plus A's row.
Ops proximalPowerOps(int n) {
  Ops o;
  for (long i = 0; i < n; ++i) {
    o.mul += n + long(n) * (n - i);
    o.add += long(n) * (n - i) + (n - i);
  }
  return o;
}

Ops se3RightJacobianInverseOps() {
  Ops o;
  // 40 terms: 1 division, P^(k+1) and C_(k+1) (81 products, 81 sums), the 18 scaled sums.
  o.div = 40;
  o.add = 40L * (81 + 18);
  o.mul = 40L * (81 + 18);
  // The 3 x 3 inverse by cofactors (18 products, 9 differences, det 3 + 2, 1
  // division, 9 scalings), the corner -A^-1 B A^-1 (two 3 x 3 products), 9 negations.
  o.mul += 18 + 3 + 9 + 54;
  o.add += 9 + 2 + 36;
  o.div += 1;
  o.neg += 9;
  return o;
}

// The rows of P = M^-1 - W Lt computed together up to their block's last
// column (the rest mirrored): a template instance of the product per block.
constexpr int kSymmetricRows = 8;

std::string emitConstrainedDynamicsDerivatives(Emit& e, const BodyTangents& t) {
  const Plan& plan = e.plan;
  const int nv = plan.nv, nc = plan.nc;
  if (nv == 0)
    fail("layout", "functions", "'constrained_dynamics_derivatives' is not generated for a robot without joints (nv = 0)");
  const auto array = [&](const std::string& base, int size, const std::string& comment) {
    e.ws.member(base, size, 0, comment);
    return "w." + base;
  };
  const std::string minv = array("cdd_Minv", nv * nv, "M^-1 (constrained_dynamics_derivatives)");
  const std::string dq = array("cdd_dtau_dq", nv * nv, "d tau / dq at (q, v, qdd*, lambda*) (constrained_dynamics_derivatives)");
  const std::string dv = array("cdd_dtau_dv", nv * nv, "d tau / dv at (q, v, qdd*, lambda*) (constrained_dynamics_derivatives)");
  RowMembers rows;
  std::string Ct, minvjt, G, Lf, S, PLt, LtS, Y;
  const int w2 = nv + nc;  // the row length of [P | Lt^T], [Lt | -S_K] and Y
  if (nc > 0) {
    rows.J = "cdd_J", rows.R2 = "cdd_R2";
    array(rows.J, nc * nv, "J (nc x nv; constrained_dynamics_derivatives)");
    array(rows.R2, 2 * nc * nv, "R2 = d a*/dx - d alpha/dx, x = q, v side by side (constrained_dynamics_derivatives)");
    Ct = array("cdd_JMinv", nc * nv, "J M^-1 (constrained_dynamics_derivatives)");
    minvjt = array("cdd_MinvJt", nv * nc, "W = M^-1 J^T (constrained_dynamics_derivatives)");
    G = array("cdd_G", nc * nc, "G = J M^-1 J^T (constrained_dynamics_derivatives)");
    Lf = array("cdd_Lf", nc * nc, "G + I/mu = L L^T, 1/L_jj on the diagonal (constrained_dynamics_derivatives)");
    S = array("cdd_S", nc * nc, "S_K, the K proximal steps as one operator (constrained_dynamics_derivatives)");
    PLt = array("cdd_PLt", nv * w2, "[P | Lt^T], P = d qdd / d tau, Lt = d lambda / d tau (constrained_dynamics_derivatives)");
    LtS = array("cdd_LtS", nc * w2, "[Lt | -S_K] (constrained_dynamics_derivatives)");
    Y = array("cdd_Y", nv * w2, "[d qdd / dx | d lambda / dx]^T, x = q or v (constrained_dynamics_derivatives)");
  }
  // Everything the host and its parts read is in workspace members (the sweep's
  // slots in `t`): no pass output moves in.
  e.fn.live() = Live{};
  e.fn.beginHost("cdd", nullptr);
  const std::vector<std::string> names = {"q", "v", "tau", "s", "w", "qdd", "lambda", "dqdd_dq", "dqdd_dv",
                                          "dqdd_dtau", "dlambda_dq", "dlambda_dv", "dlambda_dtau"};
  CodeBuilder& host = e.cb();
  // prox_pv's kinematics pass writes the joint transforms M^-1 reads (no
  // second transforms pass), its elimination U and D^-1 of the same q (M^-1
  // reads them, docs/derivatives.md section 5).
  host.line("prox_pv(q, v, tau, s, w, qdd, lambda);", {}, names);
  host.line(fmt::format("mass_matrix_inverse_factored(q, w, {});", minv), {}, names);
  // The sweep at the solution reads prox_pv's kinematics state (same q, v): the
  // joint transforms, v and c, which its elimination does not write.
  host.line(fmt::format("tangent_sweep(q, v, qdd, lambda, w, {}, {});", dq, dv), {}, names);
  OpCount ops;
  if (nc == 0) {
    // X_q = -M^-1 dtau_dq, X_v = -M^-1 dtau_dv over dtau's nonzero entries, X_tau = M^-1.
    const std::string xt = array("cdd_Xt", nv * nv, "d qdd / dq or d qdd / dv, transposed (constrained_dynamics_derivatives)");
    minvTimesDtau(e, t, minv, dq, dv, xt, names);
    CodeBuilder& cb = e.cb();
    cb.line(fmt::format("for (int k = 0; k < {}; ++k) dqdd_dtau[k] = {}[k];", nv * nv, minv), {}, names);
    for (const char* p : {"dlambda_dq", "dlambda_dv", "dlambda_dtau"})
      cb.line(fmt::format("static_cast<void>({});", p), {}, names);
    return e.fn.endHost(names);
  }
  // The rows of an inactive constraint are zeros: its lambda is 0 and its
  // tangents too, the derivatives of the solver generated without it.
  storeActiveFactors(e, "s.active");
  host.line(fmt::format("for (int k = 0; k < {}; ++k) w.{}[k] = Scalar(0);", nc * nv, rows.J), {}, names);
  host.line(fmt::format("for (int k = 0; k < {}; ++k) w.{}[k] = Scalar(0);", 2 * nc * nv, rows.R2), {}, names);
  e.fn.beginPass("rows", "constraint rows: J and d a*/dx - d alpha/dx (x = q, v) from the sweep's world-frame vectors");
  for (int i : plan.support)
    for (int k : e.bp(i).constraints) constraintRows(e, k, t, rows);
  e.fn.endPart();
  CodeBuilder& cb = e.cb();
  // With W = M^-1 J^T and Lt = S_K W^T (= d lambda / d tau), section 3's
  // L_x = S_K (W^T R1_x - R2_x) and X_x = M^-1 R1_x - W L_x are (S_K symmetric)
  //   d qdd / d tau = P = M^-1 - W Lt, and per input x = q, v
  //   X_x^T = -dtau_dx^T P + R2_x^T Lt,   L_x^T = -dtau_dx^T Lt^T - R2_x^T S_K,
  // both in one pair of products over rows of nv + nc, Y = -dtau_dx^T [P | Lt^T]
  // + R2_x^T [Lt | -S_K]: the inputs' tangents (dtau, R2) are the sparse factors,
  // and W meets one nc x nv block, not one per input.
  const RowSpans jSpans = rowSpans(nc, rows.Jnz);
  printSpans(cb, "J_nz", jSpans);
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = Scalar(0);", nc * nv, Ct), {}, names);
  ops.once = sparseLeftProductOps(jSpans, nv);
  cb.line(fmt::format("sparse_left_product_add<{}, {}, {}>(w.{}, J_nz_start, J_nz_span, {}, Scalar(1), {});", nc, nv, nv,
                      rows.J, minv, Ct),
          {}, names, ops);
  // W = M^-1 J^T = (J M^-1)^T: M^-1 is symmetric.
  copyBlock(cb, names, minvjt, Ct, nv, nc, nv, 0, true);
  // P starts as M^-1, written here, well before the product reads its rows as
  // vectors (a vector load of entries just stored one by one stalls).
  copyBlock(cb, names, PLt, minv, nv, nv, nv, 0, false, {w2, 0, false});
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = Scalar(0);", nc * nc, G), {}, names);
  ops.once = sparseLeftProductOps(jSpans, nc);
  cb.line(fmt::format("sparse_left_product_add<{}, {}, {}>(w.{}, J_nz_start, J_nz_span, {}, Scalar(1), {});", nc, nv, nc,
                      rows.J, minvjt, G),
          {}, names, ops);
  ops.once = Ops::divisions(1);
  cb.line("const Scalar inv_mu = Scalar(1) / s.mu;", {}, names, ops);
  ops.once = denseCholeskyOps(nc);
  cb.line(fmt::format("dense_cholesky<{}>({}, inv_mu, {});", nc, G, Lf), {}, names, ops);
  // The K proximal steps on the tangents are linear: S_K = sum_j mu^(1-j)
  // (G + I/mu)^-j (j = 1..K), applied to J M^-1 and to R2's rows' paths; the
  // Settings' K at run time. Formed from A = (G + I/mu)^-1 by S := A + A S / mu
  // (S_1 = A; S_0 = 0), each step's symmetric product by its upper triangle
  // (assemble.cpp's proximal_inverse and proximal_power).
  const std::string x = array("cdd_X", nc * nc, "L^-1 of G + I/mu = L L^T (constrained_dynamics_derivatives)");
  const std::string a = array("cdd_A", nc * nc, "(G + I/mu)^-1 (constrained_dynamics_derivatives)");
  const std::string tS = array("cdd_T", nc * nc, "L^-T, then the next S_k (constrained_dynamics_derivatives)");
  cb.comment("S_K = sum_(j = 1..K) mu^(1-j) (G + I/mu)^-j: S_1 = A = (G + I/mu)^-1, S_k+1 = A + A S_k / mu");
  ops.once = proximalInverseOps(nc);
  cb.line(fmt::format("proximal_inverse<{}>({}, {}, {}, {});", nc, Lf, x, tS, a), {}, names, ops);
  ops.once = Ops::multiplications(long(nc) * nc);
  cb.line("const Scalar first = Scalar(s.iterations > 0);  // K = 0: no step, S_0 = 0", {}, names);
  cb.line(fmt::format("for (int k = 0; k < {}; ++k) {}[k] = first * {}[k];", nc * nc, S, a), {}, names, ops);
  cb.open("for (int k = 1; k < s.iterations; ++k) {", {}, names);
  ops.once = proximalPowerOps(nc);
  cb.line(fmt::format("proximal_power<{}>({}, inv_mu, {}, {});", nc, a, tS, S), {}, names, ops);
  cb.close();
  // [Lt | -S_K], then [P | Lt^T] with P = M^-1 - W Lt, and their tau blocks out.
  ops.once = denseProductOps(nc, nc, nv);
  cb.line(fmt::format("dense_product<{}, {}, {}, {}, {}>({}, {}, Scalar(1), {});", nc, nc, nv, nv, w2, S, Ct, LtS), {}, names,
          ops);
  copyBlock(cb, names, LtS, S, nc, nc, nc, 0, false, {w2, nv, true});
  // P = M^-1 - W Lt is symmetric: each block of kSymmetricRows rows up to its
  // last column (the block's diagonal and what is left of it), then the rest of
  // the upper triangle mirrored: nc nv^2 / 2 and a block's diagonal, not nc nv^2.
  for (int r0 = 0; r0 < nv; r0 += kSymmetricRows) {
    const int r1 = std::min(nv, r0 + kSymmetricRows);
    const std::string a = r0 == 0 ? minvjt : fmt::format("{} + {}", minvjt, r0 * nc);
    const std::string c = r0 == 0 ? PLt : fmt::format("{} + {}", PLt, r0 * w2);
    ops.once = denseProductAddOps(r1 - r0, nc, r1);
    cb.line(fmt::format("dense_product_add<{}, {}, {}, {}, {}>({}, {}, Scalar(-1), {});", r1 - r0, nc, r1, w2, w2, a, LtS, c),
            {}, names, ops);
  }
  for (int r0 = 0; r0 + kSymmetricRows < nv; r0 += kSymmetricRows) {  // a block's columns right of it: the later rows'
    const int r1 = r0 + kSymmetricRows;
    copyBlock(cb, names, PLt, PLt, r1 - r0, nv - r1, w2, r1 * w2 + r0, true, {w2, r0 * w2 + r1, false});
  }
  copyBlock(cb, names, PLt, LtS, nv, nc, w2, 0, true, {w2, nv, false});
  copyBlock(cb, names, "dqdd_dtau", PLt, nv, nv, w2, 0, false);
  copyBlock(cb, names, "dlambda_dtau", LtS, nc, nv, w2, 0, false);
  const std::string dtaus[2] = {dq, dv}, xs[2] = {"q", "v"};
  for (int b = 0; b < 2; ++b) {
    const RowSpans dSpans = rowSpans(nv, transpose(b == 0 ? t.dtauDq : t.dtauDv));
    const RowSpans rSpans = rowSpans(nv, transpose(rows.R2nz[b]));
    const std::string dt = fmt::format("dtau_d{}_t", xs[b]), rt = fmt::format("R2_{}_t", xs[b]);
    printSpans(cb, dt, dSpans);
    printSpans(cb, rt, rSpans);
    ops.once = sparseLeftProductOps(dSpans, w2);
    cb.line(fmt::format("sparse_transposed_product<{}, {}, {}>({}, {}_start, {}_span, {}, Scalar(-1), {});", nv, nv, w2,
                        dtaus[b], dt, dt, PLt, Y),
            {}, names, ops);
    ops.once = sparseLeftProductOps(rSpans, w2);
    const std::string r2 = b == 0 ? "w." + rows.R2 : fmt::format("w.{} + {}", rows.R2, nv);
    cb.line(fmt::format("sparse_transposed_product_add<{}, {}, {}, {}>({}, {}_start, {}_span, {}, Scalar(1), {});", nv, nc,
                        w2, 2 * nv, r2, rt, rt, LtS, Y),
            {}, names, ops);
    copyBlock(cb, names, "dqdd_d" + xs[b], Y, nv, nv, w2, 0, true);
    copyBlock(cb, names, "dlambda_d" + xs[b], Y, nc, nv, w2, nv, true);
  }
  std::string text = e.fn.endHost(names);
  e.fn.live() = Live{};
  return text;
}

}  // namespace proxgen::emit

// constrained_dynamics_derivatives (docs/derivatives.md section 3): the
// derivatives of the solution prox_pv converges to, by the implicit function
// theorem on M qdd + h + J^T lambda = tau, J qdd + gamma = a*:
//   M X + J^T L = R1 = [-dtau/dq, -dtau/dv, I],   J X = R2 = d a*/dx - d alpha/dx  (x = q, v; 0 for tau),
// L by the Settings' K proximal steps (G + I/mu) L+ = C + L/mu from 0,
// C = J M^-1 R1 - R2, and X = M^-1 (R1 - J^T L), evaluated as
// X_tau = P = M^-1 - W Lt, X_x = P R1_x + Lt^T R2_x, L_x = Lt R1_x - S_K R2_x
// (W = M^-1 J^T, Lt = S_K W^T: docs/derivatives.md section 5). The host calls
// mass_matrix_inverse, prox_pv and inverse_dynamics_derivatives (held with
// it); the constraint rows (J, R2) are printed straight-line from the sweep's
// motion tangents of the constrained bodies, the path's columns only; the
// matrix algebra (O((nv + nc) (nnz(dtau) + nnz(R2)) + nv^2 nc / 2 + nc^2 nv), plus
// K nc^3 for the proximal operator S_K) is fixed-bound loops printed once by
// assemble.cpp, the products with dtau, J and R2 over their nonzero patterns
// (constant tables of column ranges). The generic counterpart:
// algorithms/derivatives.cpp (constrainedDynamicsDerivatives, constraintRowTangents).
#include <fmt/format.h>

#include <algorithm>
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

// Jr(e)^-1 of a weld's placement error e = log6(T^-1 oMc) (6 x 6, as inputs of
// the block): log6 as the kinematics pass computes it, then the helper.
std::vector<Expr> rightJacobianInverse(Emit& e, int k, const Kinematics::Body& kb) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const std::string id = e.plan.constraints[std::size_t(k)].ident;
  CodeBuilder& cb = e.cb();
  const XSym oMc = compose(cb, kb.oM, constant(c.placement));
  weldError(cb, oMc, c, "jr", id);
  cb.line(fmt::format("Scalar jri_{}[36];", id));
  OpCount ops;
  ops.once = se3RightJacobianInverseOps();
  cb.line(fmt::format("se3_right_jacobian_inverse(jre_{0}, jri_{0});", id), {}, {}, ops);
  std::vector<Expr> out;
  for (int j = 0; j < 36; ++j) out.push_back(cb.input(fmt::format("jri_{}[{}]", id, j)));
  return out;
}

struct RowMembers {
  std::string J;   // nc x nv
  std::string R2;  // nc x 2 nv: R2's q and v columns side by side
  std::set<std::pair<int, int>> Jnz;     // J's entries written (row, column): its pattern
  std::set<std::pair<int, int>> R2nz[2];  // R2_q's and R2_v's entries written
};

// entry = f * x into member[idx] (of `size` entries), skipping exact zeros
// (the host zeroed the arrays); false for a zero.
bool storeRow(Emit& e, const std::string& base, int size, int idx, const Expr& f, const Expr& x) {
  if (x.isZero()) return false;
  CodeBuilder& cb = e.cb();
  const Expr flat = cb.flat(x);
  const Expr y = cb.mul(f, flat);
  cb.store(e.ws.member(base, size, idx, "constrained_dynamics_derivatives"), y);
  return true;
}

// One constraint's rows: J, and R2 = d a*/dx - d alpha/dx for x = q, v at
// fixed qdd (alpha = J qdd + gamma: the frame's acceleration in C, 6d; the
// classical acceleration a_lin + w x v_lin of its origin, 3d), per column of
// the body's path. The sweep's a is gravity-shifted (a_0 = -a_g): the true
// acceleration's q tangent adds R^T g x w back (w the Jacobian column's
// angular part: the body turns by w, its gravity by -w x R^T g).
void constraintRows(Emit& e, int k, const Kinematics::Body& kb, const BodyTangents& t, RowMembers& m) {
  const Constraint& c = e.sys.constraints[std::size_t(k)];
  const int i = c.body, r = c.rows(), nv = e.plan.nv;
  const bool weld = c.type == ConstraintType::Weld6D;
  CodeBuilder& cb = e.cb();
  cb.comment(rowsComment(e, k));
  const XSym P = constant(c.placement);
  const Expr f = activeFactor(e, k);
  const V6 vC = actInvMotion(cb, P, kb.v);
  std::vector<Expr> jri;
  if (weld && c.kp != 0) jri = rightJacobianInverse(e, k, kb);
  V3 err = zero3();
  if (!weld && c.kp != 0) {
    const XSym oMc = compose(cb, kb.oM, constant(c.placement));
    V3 d;
    for (int j = 0; j < 3; ++j) d[std::size_t(j)] = oMc.p[std::size_t(j)] - c.target.p[j];
    err = rotateT(cb, oMc.R, d);
    for (Expr& x : err) x = cb.flat(x, "e");
  }
  const std::size_t b = std::size_t(i);
  for (const auto& [col, slots] : t.dvv[b]) {
    const V6 dvv = load(cb, slots);
    const V6 dvq = load(cb, t.dvq[b].at(col));
    const V6 daq0 = load(cb, t.daq[b].at(col));
    const V6 dav = load(cb, t.dav[b].at(col));
    const V3 gw = cross(cb, kb.g, ang(dvv));
    V6 daq = daq0;
    for (int j = 0; j < 3; ++j) daq[std::size_t(j)] += gw[std::size_t(j)];
    const V6 J6 = actInvMotion(cb, P, dvv);
    const V6 vq = actInvMotion(cb, P, dvq);
    const V6 aq = actInvMotion(cb, P, daq);
    const V6 av = actInvMotion(cb, P, dav);
    std::vector<Expr> Aq(aq.begin(), aq.begin() + r), Av(av.begin(), av.begin() + r);
    if (!weld) {  // d(w x v) = dw x v + w x dv
      const V3 t1 = cross(cb, ang(vq), lin(vC));
      const V3 t2 = cross(cb, ang(vC), lin(vq));
      const V3 t3 = cross(cb, ang(J6), lin(vC));
      const V3 t4 = cross(cb, ang(vC), lin(J6));
      for (std::size_t j = 0; j < 3; ++j) {
        Aq[j] += t1[j] + t2[j];
        Av[j] += t3[j] + t4[j];
      }
    }
    std::vector<Expr> Sq(static_cast<std::size_t>(r)), Sv(static_cast<std::size_t>(r));
    for (std::size_t j = 0; j < std::size_t(r); ++j) {
      Sq[j] = -c.kd * vq[j];
      Sv[j] = -c.kd * J6[j];
    }
    if (c.kp != 0 && weld) {  // de = Jr(e)^-1 J6 dq
      std::vector<Expr> J6f;
      for (const Expr& x : J6) J6f.push_back(cb.flat(x));
      for (std::size_t j = 0; j < 6; ++j) {
        Expr s;
        for (std::size_t l = 0; l < 6; ++l) {
          if (J6f[l].isZero()) continue;
          const Expr p = cb.mul(jri[6 * j + l], J6f[l]);
          s += p;
        }
        Sq[j] -= c.kp * s;
      }
    } else if (c.kp != 0) {  // de = J6_lin dq + e x J6_ang dq
      const V3 ex = cross(cb, err, ang(J6));
      for (std::size_t j = 0; j < 3; ++j) Sq[j] -= c.kp * (J6[j] + ex[j]);
    }
    for (int j = 0; j < r; ++j) {
      const int nc = e.plan.nc, row = c.row + j;
      if (storeRow(e, m.J, nc * nv, row * nv + col, f, J6[std::size_t(j)])) m.Jnz.insert({row, col});
      if (storeRow(e, m.R2, 2 * nc * nv, row * 2 * nv + col, f, Sq[std::size_t(j)] - Aq[std::size_t(j)]))
        m.R2nz[0].insert({row, col});
      if (storeRow(e, m.R2, 2 * nc * nv, row * 2 * nv + nv + col, f, Sv[std::size_t(j)] - Av[std::size_t(j)]))
        m.R2nz[1].insert({row, col});
    }
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

std::string emitConstrainedDynamicsDerivatives(Emit& e, const Kinematics& kinIn, const CodeBuilder* afterKinematics,
                                               const BodyTangents& t) {
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
  Kinematics kin = kinIn;
  e.fn.live() = Live{};
  e.fn.live().kin = &kin;
  e.fn.beginHost("cdd", afterKinematics);
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
  e.fn.beginPass("rows", "constraint rows: J and d a*/dx - d alpha/dx (x = q, v) from the sweep's tangents");
  for (int i : plan.support)
    for (int k : e.bp(i).constraints) {
      e.fn.boundary(i);
      e.openBody(i, "constraint rows:");
      constraintRows(e, k, kin.b[std::size_t(i)], t, rows);
      e.cb().close();
    }
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

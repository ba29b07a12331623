// Experiment (docs/benchmarks.md, "CRBA as loops over constant tables"): three
// table-driven CRBAs written as loops over the bodies, against the generated
// straight-line mass_matrix of one case, to test whether loops that the core
// replays from its decoded-instruction cache beat the unrolled code on a large
// robot. Every joint is re-framed so that it turns about z. Free-flyer robots
// with revolute joints only (the Talos and Atlas cases). Run by crba_tables.sh.
//
//   crba_tables CASE [T t|w|s]       the largest difference to the generated M (sparse
//                                    form), then generated against a table form (t: dense,
//                                    local frames; w: dense, root frame; s: sparse, local;
//                                    default s), alternating, 21 x 20000 calls
//   crba_tables CASE c g|t|w|s N     N calls of one form, for callgrind (Ir(N) - Ir(0))
//   crba_tables CASE s               how many tree rotations are signed permutations
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>
#include <algorithm>
#include "G.hpp"
#include "proxgen/runtime.hpp"
#include "cases/cases.hpp"
using namespace proxgen;

constexpr int MAXB = 128;
struct Tab {
  int N;  // bodies incl. world; body 1 = free flyer
  int parent[MAXB], iq[MAXB], iv[MAXB];
  double ET[MAXB][9], rT[MAXB][3];
  double m[MAXB], h[MAXB][3], I[MAXB][6];  // I: xx yy zz xy xz yz about origin
};
struct Work {
  double E[MAXB][9], r[MAXB][3];
  double m[MAXB], h[MAXB][3], I[MAXB][6];
};

static Mat3 toZ(const Vec3& a) {  // R with R e_z = a
  Vec3 z = a.normalized();
  Vec3 t = std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  Vec3 x = (t - t.dot(z) * z).normalized();
  Vec3 y = z.cross(x);
  Mat3 R; R.col(0) = x; R.col(1) = y; R.col(2) = z;
  return R;
}

Tab build(const Model& mdl) {
  Tab t{};
  t.N = mdl.numBodies();
  std::vector<Mat3> Ra(t.N, Mat3::Identity());
  for (int i = 2; i < t.N; ++i) Ra[i] = toZ(mdl.bodies[i].joint.axis);
  for (int i = 1; i < t.N; ++i) {
    const Body& b = mdl.bodies[i];
    t.parent[i] = b.parent; t.iq[i] = b.joint.idx_q; t.iv[i] = b.joint.idx_v;
    Mat3 Rp = b.parent >= 1 ? Ra[b.parent] : Mat3::Identity();
    Mat3 E = Rp.transpose() * b.treePlacement.R * Ra[i];
    Vec3 r = Rp.transpose() * b.treePlacement.p;
    for (int a = 0; a < 3; ++a) { t.rT[i][a] = r[a]; for (int c = 0; c < 3; ++c) t.ET[i][3 * a + c] = E(a, c); }
    const Inertia& in = b.inertia;
    Vec3 c = Ra[i].transpose() * in.com;
    Mat3 Ic = Ra[i].transpose() * in.Ic * Ra[i];
    Mat3 C = skew(c);
    Mat3 IO = Ic - in.mass * C * C;
    t.m[i] = in.mass;
    for (int a = 0; a < 3; ++a) t.h[i][a] = in.mass * c[a];
    t.I[i][0] = IO(0, 0); t.I[i][1] = IO(1, 1); t.I[i][2] = IO(2, 2);
    t.I[i][3] = IO(0, 1); t.I[i][4] = IO(0, 2); t.I[i][5] = IO(1, 2);
  }
  return t;
}

// f' = E f, n' = E n + r x f'
static inline void actForce(const double* E, const double* r, const double* f, const double* n, double* fo, double* no) {
  double a0 = E[0] * f[0] + E[1] * f[1] + E[2] * f[2];
  double a1 = E[3] * f[0] + E[4] * f[1] + E[5] * f[2];
  double a2 = E[6] * f[0] + E[7] * f[1] + E[8] * f[2];
  double b0 = E[0] * n[0] + E[1] * n[1] + E[2] * n[2];
  double b1 = E[3] * n[0] + E[4] * n[1] + E[5] * n[2];
  double b2 = E[6] * n[0] + E[7] * n[1] + E[8] * n[2];
  fo[0] = a0; fo[1] = a1; fo[2] = a2;
  no[0] = b0 + r[1] * a2 - r[2] * a1;
  no[1] = b1 + r[2] * a0 - r[0] * a2;
  no[2] = b2 + r[0] * a1 - r[1] * a0;
}

// Every body's composite inertia starts as its own.
template <class W>
static inline void initComposite(const Tab& t, W& w) {
  for (int i = 1; i < t.N; ++i) {
    w.m[i] = t.m[i];
    for (int a = 0; a < 3; ++a) w.h[i][a] = t.h[i][a];
    for (int a = 0; a < 6; ++a) w.I[i][a] = t.I[i][a];
  }
}
// R = E I E^T, I and R symmetric as (xx yy zz xy xz yz).
static inline void rotateInertia(const double* E, const double* Ii, double* R) {
  const double S[9] = {Ii[0], Ii[3], Ii[4], Ii[3], Ii[1], Ii[5], Ii[4], Ii[5], Ii[2]};
  double T[9];
  for (int a = 0; a < 3; ++a) for (int b = 0; b < 3; ++b) T[3 * a + b] = E[3 * a] * S[b] + E[3 * a + 1] * S[3 + b] + E[3 * a + 2] * S[6 + b];
  R[0] = T[0] * E[0] + T[1] * E[1] + T[2] * E[2];
  R[1] = T[3] * E[3] + T[4] * E[4] + T[5] * E[5];
  R[2] = T[6] * E[6] + T[7] * E[7] + T[8] * E[8];
  R[3] = T[0] * E[3] + T[1] * E[4] + T[2] * E[5];
  R[4] = T[0] * E[6] + T[1] * E[7] + T[2] * E[8];
  R[5] = T[3] * E[6] + T[4] * E[7] + T[5] * E[8];
}
// The rotational inertia R (about the body origin, first moment h, rotated
// already) about a point at -r: R - [r][h] - [h + m r][r]; g = h + m r, the
// first moment about the new point. (-[a][b] = (a.b) 1 - b a^T.)
static inline void shiftInertia(double m, const double* h, const double* r, double* R, double* g) {
  for (int a = 0; a < 3; ++a) g[a] = h[a] + m * r[a];
  const double d = (r[0] * h[0] + r[1] * h[1] + r[2] * h[2]) + (g[0] * r[0] + g[1] * r[1] + g[2] * r[2]);
  R[0] += d - h[0] * r[0] - r[0] * g[0];
  R[1] += d - h[1] * r[1] - r[1] * g[1];
  R[2] += d - h[2] * r[2] - r[2] * g[2];
  R[3] += -h[0] * r[1] - r[0] * g[1];
  R[4] += -h[0] * r[2] - r[0] * g[2];
  R[5] += -h[1] * r[2] - r[1] * g[2];
}
// The free flyer's 6 x 6 block: [m 1, -[h]; [h], I] in [linear; angular] order.
static inline void rootBlock(double m, const double* h, const double* I, double* M, int nv) {
  const double B[36] = {m, 0, 0, 0, h[2], -h[1],
                        0, m, 0, -h[2], 0, h[0],
                        0, 0, m, h[1], -h[0], 0,
                        0, -h[2], h[1], I[0], I[3], I[4],
                        h[2], 0, -h[0], I[3], I[1], I[5],
                        -h[1], h[0], 0, I[4], I[5], I[2]};
  for (int a = 0; a < 6; ++a) for (int b = 0; b < 6; ++b) M[a * nv + b] = B[6 * a + b];
}

__attribute__((noinline)) void crbaTable(const Tab& t, const double* q, Work& w, double* M, int nv) {
  const int N = t.N;
  for (int i = 2; i < N; ++i) {
    double s, c; proxgen_rt::sincos(q[t.iq[i]], s, c);
    const double* T = t.ET[i];
    double* E = w.E[i];
    for (int a = 0; a < 3; ++a) {
      E[3 * a + 0] = c * T[3 * a + 0] + s * T[3 * a + 1];
      E[3 * a + 1] = -s * T[3 * a + 0] + c * T[3 * a + 1];
      E[3 * a + 2] = T[3 * a + 2];
      w.r[i][a] = t.rT[i][a];
    }
  }
  initComposite(t, w);
  for (int i = N - 1; i >= 2; --i) {
    const int vi = t.iv[i];
    double f[3] = {-w.h[i][1], w.h[i][0], 0.0};
    double n[3] = {w.I[i][4], w.I[i][5], w.I[i][2]};
    M[vi * nv + vi] = n[2];
    int j = i;
    for (;;) {
      const int p = t.parent[j];
      double fo[3], no[3];
      actForce(w.E[j], w.r[j], f, n, fo, no);
      if (p == 1) {
        for (int a = 0; a < 3; ++a) { M[a * nv + vi] = fo[a]; M[vi * nv + a] = fo[a]; M[(3 + a) * nv + vi] = no[a]; M[vi * nv + 3 + a] = no[a]; }
        break;
      }
      const int vp = t.iv[p];
      M[vp * nv + vi] = no[2]; M[vi * nv + vp] = no[2];
      for (int a = 0; a < 3; ++a) { f[a] = fo[a]; n[a] = no[a]; }
      j = p;
    }
    // Ic[p] += X Ic[i]
    const int p = t.parent[i];
    const double* E = w.E[i]; const double* r = w.r[i];
    const double m = w.m[i];
    const double* hc = w.h[i]; const double* Ii = w.I[i];
    double h[3];
    for (int a = 0; a < 3; ++a) h[a] = E[3 * a] * hc[0] + E[3 * a + 1] * hc[1] + E[3 * a + 2] * hc[2];
    // R = E Ii E^T
    double R[6];
    rotateInertia(E, Ii, R);
    // I' = R - [r][h] - [h + m r][r]: -[a][b] = (a.b) 1 - b a^T  (symmetrised sum)
    double g[3];
    shiftInertia(m, h, r, R, g);
    w.m[p] += m;
    for (int a = 0; a < 3; ++a) w.h[p][a] += h[a] + m * r[a];
    for (int a = 0; a < 6; ++a) w.I[p][a] += R[a];
  }
  // root block: [m 1, -[h]; [h], I]
  rootBlock(w.m[1], w.h[1], w.I[1], M, nv);
}


struct WorkW {
  double E[MAXB][9], p[MAXB][3], S[MAXB][6];
  double m[MAXB], h[MAXB][3], I[MAXB][6];
};
// Composite inertias and motion subspaces in the root body's frame: no walk transforms,
// each entry of M one 6-dot.
__attribute__((noinline)) void crbaWorld(const Tab& t, const double* q, WorkW& w, double* M, int nv) {
  const int N = t.N;
  for (int a = 0; a < 9; ++a) w.E[1][a] = (a % 4 == 0);
  for (int a = 0; a < 3; ++a) w.p[1][a] = 0;
  w.m[1] = t.m[1];
  for (int a = 0; a < 3; ++a) w.h[1][a] = t.h[1][a];
  for (int a = 0; a < 6; ++a) w.I[1][a] = t.I[1][a];
  for (int i = 2; i < N; ++i) {
    double s, c; proxgen_rt::sincos(q[t.iq[i]], s, c);
    const int pa = t.parent[i];
    const double* P = w.E[pa]; const double* T = t.ET[i];
    double A[9];
    for (int a = 0; a < 3; ++a) for (int b = 0; b < 3; ++b) A[3 * a + b] = P[3 * a] * T[b] + P[3 * a + 1] * T[3 + b] + P[3 * a + 2] * T[6 + b];
    double* E = w.E[i];
    for (int a = 0; a < 3; ++a) {
      E[3 * a + 0] = c * A[3 * a + 0] + s * A[3 * a + 1];
      E[3 * a + 1] = -s * A[3 * a + 0] + c * A[3 * a + 1];
      E[3 * a + 2] = A[3 * a + 2];
    }
    const double* rT = t.rT[i]; double* pw = w.p[i];
    for (int a = 0; a < 3; ++a) pw[a] = P[3 * a] * rT[0] + P[3 * a + 1] * rT[1] + P[3 * a + 2] * rT[2] + w.p[pa][a];
    const double ax[3] = {A[2], A[5], A[8]};
    double* S = w.S[i];
    S[0] = pw[1] * ax[2] - pw[2] * ax[1]; S[1] = pw[2] * ax[0] - pw[0] * ax[2]; S[2] = pw[0] * ax[1] - pw[1] * ax[0];
    S[3] = ax[0]; S[4] = ax[1]; S[5] = ax[2];
    // body inertia in the root frame about the root origin
    const double m = t.m[i]; const double* hc = t.h[i]; const double* Ii = t.I[i];
    double h[3];
    for (int a = 0; a < 3; ++a) h[a] = E[3 * a] * hc[0] + E[3 * a + 1] * hc[1] + E[3 * a + 2] * hc[2];
    double R[6];
    rotateInertia(E, Ii, R);
    const double* r = pw;
    double g[3];
    shiftInertia(m, h, r, R, g);
    w.m[i] = m;
    for (int a = 0; a < 3; ++a) w.h[i][a] = g[a];
    for (int a = 0; a < 6; ++a) w.I[i][a] = R[a];
  }
  for (int i = N - 1; i >= 2; --i) {
    const int vi = t.iv[i];
    const double m = w.m[i]; const double* h = w.h[i]; const double* I = w.I[i]; const double* S = w.S[i];
    // F = Y S, Y = [m 1, -[h]; [h], I] in [lin; ang]
    double F[6];
    F[0] = m * S[0] - (h[1] * S[5] - h[2] * S[4]);
    F[1] = m * S[1] - (h[2] * S[3] - h[0] * S[5]);
    F[2] = m * S[2] - (h[0] * S[4] - h[1] * S[3]);
    F[3] = (h[1] * S[2] - h[2] * S[1]) + I[0] * S[3] + I[3] * S[4] + I[4] * S[5];
    F[4] = (h[2] * S[0] - h[0] * S[2]) + I[3] * S[3] + I[1] * S[4] + I[5] * S[5];
    F[5] = (h[0] * S[1] - h[1] * S[0]) + I[4] * S[3] + I[5] * S[4] + I[2] * S[5];
    for (int j = i; j != 1; j = t.parent[j]) {
      const double* Sj = w.S[j];
      const double e = Sj[0] * F[0] + Sj[1] * F[1] + Sj[2] * F[2] + Sj[3] * F[3] + Sj[4] * F[4] + Sj[5] * F[5];
      const int vj = t.iv[j];
      M[vj * nv + vi] = e; M[vi * nv + vj] = e;
    }
    for (int a = 0; a < 6; ++a) { M[a * nv + vi] = F[a]; M[vi * nv + a] = F[a]; }
    const int p = t.parent[i];
    w.m[p] += m;
    for (int a = 0; a < 3; ++a) w.h[p][a] += h[a];
    for (int a = 0; a < 6; ++a) w.I[p][a] += I[a];
  }
  rootBlock(w.m[1], w.h[1], w.I[1], M, nv);
}

struct SpTab { int pr[MAXB][3]; double sg[MAXB][3]; int dense[MAXB]; };
SpTab buildSparse(const Tab& t) {
  SpTab s{};
  for (int i = 2; i < t.N; ++i) {
    int nz = 0;
    for (int a = 0; a < 9; ++a) nz += std::abs(t.ET[i][a]) > 1e-12;
    s.dense[i] = nz != 3;
    for (int a = 0; a < 3; ++a) for (int b = 0; b < 3; ++b) if (std::abs(t.ET[i][3 * a + b]) > 1e-12) { s.pr[i][a] = b; s.sg[i][a] = t.ET[i][3 * a + b] > 0 ? 1.0 : -1.0; }
  }
  return s;
}
struct WorkS { double c[MAXB], s[MAXB]; double m[MAXB], h[MAXB][3], I[MAXB][6]; };
// y = ET x (ET a signed permutation unless dense)
static inline void applyET(const Tab& t, const SpTab& sp, int i, const double* x, double* y) {
  if (sp.dense[i]) {
    const double* E = t.ET[i];
    for (int a = 0; a < 3; ++a) y[a] = E[3 * a] * x[0] + E[3 * a + 1] * x[1] + E[3 * a + 2] * x[2];
  } else {
    for (int a = 0; a < 3; ++a) y[a] = sp.sg[i][a] * x[sp.pr[i][a]];
  }
}
__attribute__((noinline)) void crbaSparse(const Tab& t, const SpTab& sp, const double* q, WorkS& w, double* M, int nv) {
  const int N = t.N;
  for (int i = 2; i < N; ++i) proxgen_rt::sincos(q[t.iq[i]], w.s[i], w.c[i]);
  initComposite(t, w);
  for (int i = N - 1; i >= 2; --i) {
    const int vi = t.iv[i];
    double f[3] = {-w.h[i][1], w.h[i][0], 0.0};
    double n[3] = {w.I[i][4], w.I[i][5], w.I[i][2]};
    M[vi * nv + vi] = n[2];
    int j = i;
    for (;;) {
      const int p = t.parent[j];
      const double c = w.c[j], s = w.s[j];
      double fz[3] = {c * f[0] - s * f[1], s * f[0] + c * f[1], f[2]};
      double nz[3] = {c * n[0] - s * n[1], s * n[0] + c * n[1], n[2]};
      double fo[3], no[3];
      applyET(t, sp, j, fz, fo);
      applyET(t, sp, j, nz, no);
      const double* r = t.rT[j];
      no[0] += r[1] * fo[2] - r[2] * fo[1];
      no[1] += r[2] * fo[0] - r[0] * fo[2];
      no[2] += r[0] * fo[1] - r[1] * fo[0];
      if (p == 1) {
        for (int a = 0; a < 3; ++a) { M[a * nv + vi] = fo[a]; M[vi * nv + a] = fo[a]; M[(3 + a) * nv + vi] = no[a]; M[vi * nv + 3 + a] = no[a]; }
        break;
      }
      const int vp = t.iv[p];
      M[vp * nv + vi] = no[2]; M[vi * nv + vp] = no[2];
      for (int a = 0; a < 3; ++a) { f[a] = fo[a]; n[a] = no[a]; }
      j = p;
    }
    const int p = t.parent[i];
    const double c = w.c[i], s = w.s[i];
    const double m = w.m[i];
    const double* hc = w.h[i]; const double* Ii = w.I[i];
    // rotz: h, and I -> Rz I Rz^T (xx yy zz xy xz yz)
    double hz[3] = {c * hc[0] - s * hc[1], s * hc[0] + c * hc[1], hc[2]};
    const double cc = c * c, ss = s * s, cs = c * s;
    double Iz[9];
    Iz[0] = cc * Ii[0] - 2 * cs * Ii[3] + ss * Ii[1];
    Iz[4] = ss * Ii[0] + 2 * cs * Ii[3] + cc * Ii[1];
    Iz[1] = Iz[3] = cs * (Ii[0] - Ii[1]) + (cc - ss) * Ii[3];
    Iz[2] = Iz[6] = c * Ii[4] - s * Ii[5];
    Iz[5] = Iz[7] = s * Ii[4] + c * Ii[5];
    Iz[8] = Ii[2];
    double h[3], R[6];
    applyET(t, sp, i, hz, h);
    if (sp.dense[i]) {
      const double* E = t.ET[i];
      double T[9];
      for (int a = 0; a < 3; ++a) for (int b = 0; b < 3; ++b) T[3 * a + b] = E[3 * a] * Iz[b] + E[3 * a + 1] * Iz[3 + b] + E[3 * a + 2] * Iz[6 + b];
      R[0] = T[0] * E[0] + T[1] * E[1] + T[2] * E[2];
      R[1] = T[3] * E[3] + T[4] * E[4] + T[5] * E[5];
      R[2] = T[6] * E[6] + T[7] * E[7] + T[8] * E[8];
      R[3] = T[0] * E[3] + T[1] * E[4] + T[2] * E[5];
      R[4] = T[0] * E[6] + T[1] * E[7] + T[2] * E[8];
      R[5] = T[3] * E[6] + T[4] * E[7] + T[5] * E[8];
    } else {
      const int* pr = sp.pr[i]; const double* sg = sp.sg[i];
      R[0] = Iz[4 * pr[0]]; R[1] = Iz[4 * pr[1]]; R[2] = Iz[4 * pr[2]];
      R[3] = sg[0] * sg[1] * Iz[3 * pr[0] + pr[1]];
      R[4] = sg[0] * sg[2] * Iz[3 * pr[0] + pr[2]];
      R[5] = sg[1] * sg[2] * Iz[3 * pr[1] + pr[2]];
    }
    const double* r = t.rT[i];
    double g[3];
    shiftInertia(m, h, r, R, g);
    w.m[p] += m;
    for (int a = 0; a < 3; ++a) w.h[p][a] += g[a];
    for (int a = 0; a < 6; ++a) w.I[p][a] += R[a];
  }
  rootBlock(w.m[1], w.h[1], w.I[1], M, nv);
}

int main(int argc, char** argv) {
  Case c = loadCase("/work/shared/models/cases.yaml", argv[1]);
  System sys = loadCaseSystem(c);
  static Tab t = build(sys.model);
  static Work w; static WorkW ww; static SpTab sp = buildSparse(t); static WorkS ws;
  static G::Workspace gw{};
  constexpr int nq = G::nq, nv = G::nv;
  const int K = 1000;
  std::vector<double> Q(K * nq);
  std::mt19937 g(1); std::normal_distribution<double> d(0, 1);
  for (double& x : Q) x = d(g);
  std::vector<double> M1(nv * nv), M2(nv * nv);
  double err = 0, scale = 0;
  for (int k = 0; k < K; ++k) {
    G::mass_matrix(&Q[k * nq], gw, M1.data());
    crbaSparse(t, sp, &Q[k * nq], ws, M2.data(), nv);
    for (int e = 0; e < nv * nv; ++e) { err = std::max(err, std::abs(M1[e] - M2[e])); scale = std::max(scale, std::abs(M1[e])); }
  }
  if (argc > 2 && argv[2][0] == 's') { int perm = 0, zr = 0; for (int i = 2; i < t.N; ++i) { int nz = 0; for (int a = 0; a < 9; ++a) nz += std::abs(t.ET[i][a]) > 1e-12; perm += nz == 3; for (int a = 0; a < 3; ++a) zr += std::abs(t.rT[i][a]) < 1e-12; } std::printf("bodies %d, ET signed-permutation %d, zero r entries %d of %d\n", t.N - 2, perm, zr, 3 * (t.N - 2)); return 0; }
  std::printf("max |diff| %.3g (max |M| %.3g)\n", err, scale);
  if (argc > 2 && argv[2][0] == 'c') {  // count mode: argv[3] = 'g' or 't', argv[4] = calls
    int n = std::atoi(argv[4]);
    for (int k = 0; k < n; ++k) {
      if (argv[3][0] == 'g') G::mass_matrix(&Q[(k % K) * nq], gw, M1.data());
      else if (argv[3][0] == 't') crbaTable(t, &Q[(k % K) * nq], w, M2.data(), nv); else if (argv[3][0] == 'w') crbaWorld(t, &Q[(k % K) * nq], ww, M2.data(), nv); else crbaSparse(t, sp, &Q[(k % K) * nq], ws, M2.data(), nv);
    }
    return 0;
  }
  const char form = argc > 3 && argv[2][0] == 'T' ? argv[3][0] : 's';
  std::vector<double> tg, tt;
  const int calls = 20000;
  for (int rep = 0; rep < 21; ++rep) {
    auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k) G::mass_matrix(&Q[(k % K) * nq], gw, M1.data());
    auto t1 = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k) {
      const double* qk = &Q[(k % K) * nq];
      if (form == 't') crbaTable(t, qk, w, M2.data(), nv);
      else if (form == 'w') crbaWorld(t, qk, ww, M2.data(), nv);
      else crbaSparse(t, sp, qk, ws, M2.data(), nv);
    }
    auto t2 = std::chrono::steady_clock::now();
    tg.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / calls);
    tt.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count() / calls);
  }
  std::sort(tg.begin(), tg.end()); std::sort(tt.begin(), tt.end());
  std::printf("generated median %.3f us fastest %.3f; table median %.3f fastest %.3f; table/gen %.3f (form %c)\n", tg[10], tg[0], tt[10], tt[0], tt[10] / tg[10], form);
}

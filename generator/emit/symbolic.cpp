#include "emit/symbolic.hpp"

namespace proxgen::emit {

V3 constant(const Vec3& x) { return {Expr(x[0]), Expr(x[1]), Expr(x[2])}; }

M3 constant(const Mat3& m) {
  M3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[std::size_t(3 * i + j)] = Expr(m(i, j));
  return r;
}

V6 constant(const Vec6& x) {
  V6 r;
  for (int i = 0; i < 6; ++i) r[std::size_t(i)] = Expr(x[i]);
  return r;
}

Sym constant(const Mat6& m) {
  Sym r(6);
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) r(i, j) = Expr(m(i, j));
  return r;
}

XSym constant(const SE3& X) { return {constant(X.R), constant(X.p)}; }
V3 zero3() { return {Expr(), Expr(), Expr()}; }
V6 zero6() { return {Expr(), Expr(), Expr(), Expr(), Expr(), Expr()}; }

bool isSignedPermutation(const M3& R) {
  for (int i = 0; i < 3; ++i) {
    int nonzero = 0;
    for (int j = 0; j < 3; ++j) {
      const Expr& e = at(R, i, j);
      if (e.isZero()) continue;
      if (!e.isConstant() || (e.constant() != 1.0 && e.constant() != -1.0)) return false;
      ++nonzero;
    }
    if (nonzero != 1) return false;
  }
  return true;
}

// a*b + s c*d, the two products made in this order. C++ leaves the order in
// which an operator's operands are evaluated unspecified (gcc and clang differ),
// and the order in which products are made decides the order of terms in the
// emitted text: every expression that makes two products says which is first,
// so a proxgen built by any compiler writes the same bytes.
Expr mulAdd(CodeBuilder& cb, const Expr& a, const Expr& b, double s, const Expr& c, const Expr& d) {
  const Expr first = cb.mul(a, b);
  return first + s * cb.mul(c, d);
}

namespace {

bool isIdentity(const M3& R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Expr& e = at(R, i, j);
      if (!e.isConstant() || e.constant() != (i == j ? 1.0 : 0.0)) return false;
    }
  return true;
}

bool isZero(const V3& p) { return p[0].isZero() && p[1].isZero() && p[2].isZero(); }

// Operands of a product with a dense factor become temporaries first, so a
// long sum is computed once and not re-expanded into every row.
V3 flatFor(CodeBuilder& cb, const M3& R, const V3& x) {
  if (isSignedPermutation(R)) return x;
  return {cb.flat(x[0]), cb.flat(x[1]), cb.flat(x[2])};
}

using G3 = std::array<Expr, 9>;  // general 3x3, row-major

Expr g(const G3& m, int i, int j) { return m[std::size_t(3 * i + j)]; }

bool sameExpr(const Expr& a, const Expr& b) { return (a - b).isZero(); }

// A rotation about coordinate axis `a` by a run-time angle: R(a,a) = 1, zeros
// elsewhere in that row and column, and R = [c -x; x c] in the plane (i, j).
bool planarRotation(const M3& R, int& a, int& i, int& j) {
  for (a = 0; a < 3; ++a) {
    i = (a + 1) % 3;
    j = (a + 2) % 3;
    if (!at(R, a, a).isConstant() || at(R, a, a).constant() != 1.0) continue;
    if (!at(R, a, i).isZero() || !at(R, a, j).isZero() || !at(R, i, a).isZero() || !at(R, j, a).isZero()) continue;
    return !at(R, i, i).isConstant() && sameExpr(at(R, i, i), at(R, j, j)) && !at(R, j, i).isConstant() &&
           sameExpr(at(R, i, j), -at(R, j, i));
  }
  return false;
}

// R X R^T for a planar rotation, through the double angle: in the plane a
// symmetric 2x2 block [p q; q r] becomes [m + d, h S2 + q C2; .., m - d], d = h C2 - q S2,
// with m, h = (p +- r) / 2, C2 = c^2 - x^2, S2 = 2 c x (x = R(j,i)); the
// antisymmetric part of a general block is invariant. About half the products
// of the plain R X R^T.
G3 rotateBlockPlanar(CodeBuilder& cb, const M3& R, const G3& X, bool symmetric, int a, int i, int j) {
  const Expr c = at(R, i, i), x = at(R, j, i);
  const Expr C2 = cb.flat(mulAdd(cb, c, c, -1.0, x, x), "C2");
  const Expr S2 = cb.flat(2.0 * cb.mul(c, x), "S2");
  auto idx = [](int r, int col) { return std::size_t(3 * r + col); };
  G3 out = X;
  // Column a (and row a): rotated as vectors.
  out[idx(i, a)] = mulAdd(cb, c, X[idx(i, a)], 1.0, at(R, i, j), X[idx(j, a)]);
  out[idx(j, a)] = mulAdd(cb, x, X[idx(i, a)], 1.0, c, X[idx(j, a)]);
  if (symmetric) {
    out[idx(a, i)] = out[idx(i, a)];
    out[idx(a, j)] = out[idx(j, a)];
  } else {
    out[idx(a, i)] = mulAdd(cb, c, X[idx(a, i)], 1.0, at(R, i, j), X[idx(a, j)]);
    out[idx(a, j)] = mulAdd(cb, x, X[idx(a, i)], 1.0, c, X[idx(a, j)]);
  }
  const Expr p = X[idx(i, i)], r = X[idx(j, j)];
  const Expr q = symmetric ? X[idx(i, j)] : 0.5 * (X[idx(i, j)] + X[idx(j, i)]);
  const Expr k = symmetric ? Expr() : 0.5 * (X[idx(i, j)] - X[idx(j, i)]);
  const Expr h = cb.flat(0.5 * (p - r), "h"), m = cb.flat(0.5 * (p + r), "m");
  // r' from its own formula, not p + r - p': no cancellation when r' << p'.
  const Expr d = cb.flat(mulAdd(cb, h, C2, -1.0, q, S2), "d");
  const Expr qq = cb.flat(mulAdd(cb, h, S2, 1.0, q, C2), "qq");
  out[idx(i, i)] = m + d;
  out[idx(j, j)] = m - d;
  out[idx(i, j)] = qq + k;
  out[idx(j, i)] = qq - k;
  return out;
}

// R X R^T of a 3x3 block (X general or symmetric), through T = R X.
G3 rotateBlock(CodeBuilder& cb, const M3& R, const G3& X, bool symmetric) {
  int a, i, j;
  if (planarRotation(R, a, i, j)) return rotateBlockPlanar(cb, R, X, symmetric, a, i, j);
  const bool flatten = !isSignedPermutation(R);
  G3 T;
  for (int j = 0; j < 3; ++j)
    for (int l = 0; l < 3; ++l) {
      Expr s;
      for (int k = 0; k < 3; ++k) s += cb.mul(at(R, j, k), g(X, k, l));
      T[std::size_t(3 * j + l)] = flatten ? cb.flat(s) : s;
    }
  G3 out;
  for (int j = 0; j < 3; ++j)
    for (int l = symmetric ? j : 0; l < 3; ++l) {
      Expr s;
      for (int k = 0; k < 3; ++k) s += cb.mul(g(T, j, k), at(R, l, k));
      out[std::size_t(3 * j + l)] = s;
      if (symmetric) out[std::size_t(3 * l + j)] = s;
    }
  return out;
}

G3 mul3(CodeBuilder& cb, const G3& a, const G3& b) {
  G3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Expr s;
      for (int k = 0; k < 3; ++k) s += cb.mul(g(a, i, k), g(b, k, j));
      r[std::size_t(3 * i + j)] = s;
    }
  return r;
}

G3 transpose(const G3& a) {
  G3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[std::size_t(3 * i + j)] = g(a, j, i);
  return r;
}

void flatten3(CodeBuilder& cb, G3& a) {
  for (Expr& e : a) e = cb.flat(e);
}

}  // namespace

M3 skewOf(const V3& p) { return {Expr(), -p[2], p[1], p[2], Expr(), -p[0], -p[1], p[0], Expr()}; }

V3 rotate(CodeBuilder& cb, const M3& R, const V3& x0) {
  const V3 x = flatFor(cb, R, x0);
  V3 r;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) r[std::size_t(i)] += cb.mul(at(R, i, k), x[std::size_t(k)]);
  return r;
}

V3 rotateT(CodeBuilder& cb, const M3& R, const V3& x0) {
  const V3 x = flatFor(cb, R, x0);
  V3 r;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) r[std::size_t(i)] += cb.mul(at(R, k, i), x[std::size_t(k)]);
  return r;
}

V3 cross(CodeBuilder& cb, const V3& a, const V3& b) {
  return {mulAdd(cb, a[1], b[2], -1.0, a[2], b[1]), mulAdd(cb, a[2], b[0], -1.0, a[0], b[2]),
          mulAdd(cb, a[0], b[1], -1.0, a[1], b[0])};
}

V3 lin(const V6& x) { return {x[0], x[1], x[2]}; }
V3 ang(const V6& x) { return {x[3], x[4], x[5]}; }
V6 stack(const V3& l, const V3& a) { return {l[0], l[1], l[2], a[0], a[1], a[2]}; }

V6 add(const V6& a, const V6& b) {
  V6 r;
  for (std::size_t i = 0; i < 6; ++i) r[i] = a[i] + b[i];
  return r;
}

V6 sub(const V6& a, const V6& b) {
  V6 r;
  for (std::size_t i = 0; i < 6; ++i) r[i] = a[i] - b[i];
  return r;
}

V6 scale(CodeBuilder& cb, const Expr& k, const V6& x) {
  V6 r;
  for (std::size_t i = 0; i < 6; ++i) r[i] = cb.mul(k, x[i]);
  return r;
}

XSym compose(CodeBuilder& cb, const XSym& A, const XSym& B) {
  XSym r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Expr s;
      for (int k = 0; k < 3; ++k) s += cb.mul(at(A.R, i, k), at(B.R, k, j));
      r.R[std::size_t(3 * i + j)] = s;
    }
  const V3 t = rotate(cb, A.R, B.p);
  for (std::size_t i = 0; i < 3; ++i) r.p[i] = t[i] + A.p[i];
  return r;
}

V6 actInvMotion(CodeBuilder& cb, const XSym& X, const V6& m) {
  V3 l = lin(m);
  const V3 a = ang(m);
  if (!isZero(X.p)) {
    const V3 pxa = cross(cb, X.p, a);
    for (std::size_t i = 0; i < 3; ++i) l[i] -= pxa[i];
  }
  const V3 rl = rotateT(cb, X.R, l);  // before R^T a: see mulAdd
  return stack(rl, rotateT(cb, X.R, a));
}

V6 actForce(CodeBuilder& cb, const XSym& X, const V6& f) {
  V3 l = rotate(cb, X.R, lin(f));
  V3 a = rotate(cb, X.R, ang(f));
  if (!isZero(X.p)) {
    for (Expr& e : l) e = cb.flat(e);  // R f_l once, for the result and for p x (R f_l)
    const V3 pxl = cross(cb, X.p, l);
    for (std::size_t i = 0; i < 3; ++i) a[i] += pxl[i];
  }
  return stack(l, a);
}

V6 crossMotion(CodeBuilder& cb, const V6& v, const V6& m) {
  const V3 a = cross(cb, ang(v), lin(m)), b = cross(cb, lin(v), ang(m)), c = cross(cb, ang(v), ang(m));
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2]};
}

V6 crossForce(CodeBuilder& cb, const V6& v, const V6& f) {
  const V3 a = cross(cb, ang(v), lin(f)), b = cross(cb, ang(v), ang(f)), c = cross(cb, lin(v), lin(f));
  return {a[0], a[1], a[2], b[0] + c[0], b[1] + c[1], b[2] + c[2]};
}

V6 mul(CodeBuilder& cb, const Sym& M, const V6& x) {
  V6 r;
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 6; ++k) r[std::size_t(i)] += cb.mul(M(i, k), x[std::size_t(k)]);
  return r;
}

Expr dot(CodeBuilder& cb, const V6& a, const V6& b) {
  Expr s;
  for (std::size_t i = 0; i < 6; ++i) s += cb.mul(a[i], b[i]);
  return s;
}

Sym congruence(CodeBuilder& cb, const XSym& X, const Sym& M) {
  G3 A, B, C;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      A[std::size_t(3 * i + j)] = M(i, j);
      B[std::size_t(3 * i + j)] = M(i, 3 + j);
      C[std::size_t(3 * i + j)] = M(3 + i, 3 + j);
    }
  if (!isIdentity(X.R)) {
    A = rotateBlock(cb, X.R, A, true);
    B = rotateBlock(cb, X.R, B, false);
    C = rotateBlock(cb, X.R, C, true);
  }
  if (!isZero(X.p)) {
    // [A, B - A P; (B - A P)^T, C + P (B - A P) - B^T P] with P = [p]x.
    const G3 P = skewOf(X.p);
    flatten3(cb, A);
    flatten3(cb, B);
    G3 N = mul3(cb, A, P);
    for (std::size_t k = 0; k < 9; ++k) N[k] = B[k] - N[k];
    flatten3(cb, N);
    const G3 PN = mul3(cb, P, N), BtP = mul3(cb, transpose(B), P);
    for (std::size_t k = 0; k < 9; ++k) C[k] = C[k] + PN[k] - BtP[k];
    B = N;
  }
  Sym out(6);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (j >= i) out(i, j) = g(A, i, j);
      out(i, 3 + j) = g(B, i, j);
      if (j >= i) out(3 + i, 3 + j) = g(C, i, j);
    }
  return out;
}

Rigid rigidOf(const Sym& M) {
  Rigid r;
  r.m = M(0, 0);
  r.h = {M(1, 5), M(2, 3), M(0, 4)};  // the coupling block M(i, 3 + j) is -[h]x
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) r.I(i, j) = M(3 + i, 3 + j);
  return r;
}

Sym spatial(const Rigid& r) {
  Sym M(6);
  for (int i = 0; i < 3; ++i) {
    M(i, i) = r.m;
    for (int j = i; j < 3; ++j) M(3 + i, 3 + j) = r.I(i, j);
  }
  const G3 H = skewOf(r.h);  // [h]x; the coupling block is its transpose, -[h]x
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, 3 + j) = -g(H, i, j);
  return M;
}

Rigid rigidToParent(CodeBuilder& cb, const XSym& X, const Rigid& r) {
  Rigid out;
  out.m = r.m;
  V3 h = r.h;
  G3 I;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I[std::size_t(3 * i + j)] = r.I(i, j);
  if (!isIdentity(X.R)) {
    h = rotate(cb, X.R, h);
    I = rotateBlock(cb, X.R, I, true);
  }
  if (isZero(X.p)) {
    out.h = h;
  } else {
    // With a = R h and p the shift: h' = a + m p and, from
    // I' = R I R^T - [a]x[p]x - [p]x[a]x - m [p]x^2 ([u]x[w]x = w u^T - (u.w) 1),
    // I'_ij = I_ij - a_i p_j - p_i a_j - m p_i p_j (i != j) and
    // I'_ii = I_ii + sum over k != i of (2 p_k a_k + m p_k^2).
    for (Expr& e : h) e = cb.flat(e);
    const V3& p = X.p;
    for (std::size_t i = 0; i < 3; ++i) out.h[i] = h[i] + cb.mul(r.m, p[i]);
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        Expr e = g(I, i, j);
        const std::size_t u = std::size_t(i), w = std::size_t(j);
        if (i == j) {
          for (std::size_t k = 0; k < 3; ++k)
            if (k != u) e += 2.0 * cb.mul(p[k], h[k]) + cb.mul(r.m, cb.mul(p[k], p[k]));
        } else {
          e -= cb.mul(h[u], p[w]) + cb.mul(p[u], h[w]) + cb.mul(r.m, cb.mul(p[u], p[w]));
        }
        out.I(i, j) = e;
      }
    return out;
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) out.I(i, j) = g(I, i, j);
  return out;
}

void flatten(CodeBuilder& cb, V6& x, const std::string& hint) {
  for (Expr& e : x) e = cb.flat(e, hint);
}

void flatten(CodeBuilder& cb, Sym& M, const std::string& hint) {
  for (int k = 0; k < M.packedSize(); ++k) M.packed(k) = cb.flat(M.packed(k), hint);
}

}  // namespace proxgen::emit

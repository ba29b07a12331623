// Spatial algebra over Expr (expr.hpp): the same operations as model/spatial.hpp,
// written once with symbolic entries, so a constant zero or one anywhere (in a
// tree transform, an inertia, a joint axis, a structural zero of the
// recursion) drops out of the printed code by itself. Conventions are
// spatial.hpp's: [linear; angular], a placement {R, p} maps child coordinates
// to parent coordinates.
#pragma once

#include <array>
#include <vector>

#include "emit/expr.hpp"
#include "model/spatial.hpp"

namespace proxgen::emit {

using V3 = std::array<Expr, 3>;
using V6 = std::array<Expr, 6>;
using M3 = std::array<Expr, 9>;  // row-major

/// Symmetric n x n matrix, upper triangle packed row by row.
class Sym {
 public:
  Sym() = default;
  explicit Sym(int n) : n_(n), e_(std::size_t(n * (n + 1) / 2)) {}
  int size() const { return n_; }
  static int index(int n, int i, int j) {
    if (i > j) std::swap(i, j);
    return i * n - i * (i - 1) / 2 + (j - i);
  }
  Expr& operator()(int i, int j) { return e_[std::size_t(index(n_, i, j))]; }
  const Expr& operator()(int i, int j) const { return e_[std::size_t(index(n_, i, j))]; }
  Expr& packed(int k) { return e_[std::size_t(k)]; }
  const Expr& packed(int k) const { return e_[std::size_t(k)]; }
  int packedSize() const { return int(e_.size()); }

 private:
  int n_ = 0;
  std::vector<Expr> e_;
};

/// A placement with symbolic entries.
struct XSym {
  M3 R;
  V3 p;
};

V3 constant(const Vec3& x);
M3 constant(const Mat3& m);
V6 constant(const Vec6& x);
Sym constant(const Mat6& m);
XSym constant(const SE3& X);
V3 zero3();
V6 zero6();
inline Expr at(const M3& m, int i, int j) { return m[std::size_t(3 * i + j)]; }

/// True when R is a signed permutation with entries +-1 (applying it only
/// picks and negates components: nothing worth a temporary).
bool isSignedPermutation(const M3& R);

V3 rotate(CodeBuilder& cb, const M3& R, const V3& x);     // R x
V3 rotateT(CodeBuilder& cb, const M3& R, const V3& x);    // R^T x
V3 cross(CodeBuilder& cb, const V3& a, const V3& b);
/// [p]x, the cross product with p as a matrix: [p]x x = p x x.
M3 skewOf(const V3& p);
/// a*b + s c*d with the products made in this order, whatever the compiler
/// (the order decides the emitted text; C++ does not fix an operator's).
Expr mulAdd(CodeBuilder& cb, const Expr& a, const Expr& b, double s, const Expr& c, const Expr& d);
V3 lin(const V6& x);
V3 ang(const V6& x);
V6 stack(const V3& l, const V3& a);
V6 add(const V6& a, const V6& b);
V6 sub(const V6& a, const V6& b);
V6 scale(CodeBuilder& cb, const Expr& k, const V6& x);

/// A * B (placements compose like SE3::operator*).
XSym compose(CodeBuilder& cb, const XSym& A, const XSym& B);
V6 actInvMotion(CodeBuilder& cb, const XSym& X, const V6& m);  // parent -> child (motion)
V6 actForce(CodeBuilder& cb, const XSym& X, const V6& f);      // child -> parent (force)
V6 crossMotion(CodeBuilder& cb, const V6& v, const V6& m);
V6 crossForce(CodeBuilder& cb, const V6& v, const V6& f);
V6 mul(CodeBuilder& cb, const Sym& M, const V6& x);           // 6x6 symmetric times vector
Expr dot(CodeBuilder& cb, const V6& a, const V6& b);

/// F M F^T with F the force transform of X ([R 0; [p]R R]): a child's
/// articulated inertia seen from the parent. Rotation first, then the shift.
Sym congruence(CodeBuilder& cb, const XSym& X, const Sym& M);

/// A rigid-body inertia (one body's, or a composite of bodies') by its ten
/// parameters in the body frame: the mass m (a constant: a sum of the model's
/// masses), the first moment h = m c (c the centre of mass) and the rotational
/// inertia I about the frame's origin. As a 6 x 6 in [linear; angular] it is
/// [m 1, -[h]x; [h]x, I]: CRBA carries composite inertias in this form, 9
/// entries that vary with q where the general symmetric 6 x 6 of an
/// articulated inertia has 21 (its mass block is m 1, its coupling block
/// skew; the symbolic algebra cannot see either through a rotation).
struct Rigid {
  Expr m;
  V3 h = zero3();
  Sym I{3};
};
/// The parameters of M, which must have that form (a body's own inertia).
Rigid rigidOf(const Sym& M);
/// The 6 x 6 of r.
Sym spatial(const Rigid& r);
/// r seen from the parent (X maps child to parent coordinates): m, R h + m p,
/// and R I R^T shifted by the parallel-axis terms of p; the same inertia as
/// congruence(X, spatial(r)) without its structural zeros and repeats.
Rigid rigidToParent(CodeBuilder& cb, const XSym& X, const Rigid& r);

/// Every non-trivial entry as a temporary (before it enters many products).
void flatten(CodeBuilder& cb, V6& x, const std::string& hint);
void flatten(CodeBuilder& cb, Sym& M, const std::string& hint);

}  // namespace proxgen::emit

// Spatial algebra for the generic solvers: placements, motion/force transforms,
// cross products and rigid-body inertias.
//
// Convention (Pinocchio's): spatial vectors are [linear; angular], expressed in
// the coordinates of a body frame. A placement `SE3 M` of frame B in frame A
// maps B-coordinates to A-coordinates: x_A = M.R * x_B + M.p.
//
//   M.actMotion(m_B)     motion in B coords  -> A coords
//   M.actInvMotion(m_A)  motion in A coords  -> B coords   (Featherstone's X_B<-A)
//   M.actForce(f_B)      force  in B coords  -> A coords   (X^T, child to parent)
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace proxgen {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

inline Mat3 skew(const Vec3& a) {
  Mat3 S;
  S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return S;
}

inline Eigen::Ref<const Vec3> lin(const Vec6& v) { return v.head<3>(); }
inline Eigen::Ref<const Vec3> ang(const Vec6& v) { return v.tail<3>(); }

inline Vec6 stack(const Vec3& l, const Vec3& a) {
  Vec6 r;
  r << l, a;
  return r;
}

/// Motion cross product v x m.
inline Vec6 crossMotion(const Vec6& v, const Vec6& m) {
  const Vec3 vl = v.head<3>(), w = v.tail<3>();
  return stack(w.cross(m.head<3>()) + vl.cross(m.tail<3>()), w.cross(m.tail<3>()));
}

/// Force cross product v x* f.
inline Vec6 crossForce(const Vec6& v, const Vec6& f) {
  const Vec3 vl = v.head<3>(), w = v.tail<3>();
  return stack(w.cross(f.head<3>()), w.cross(f.tail<3>()) + vl.cross(f.head<3>()));
}

/// Placement of a frame B in a frame A.
struct SE3 {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();

  static SE3 Identity() { return {}; }
  SE3 operator*(const SE3& o) const { return {R * o.R, R * o.p + p}; }
  SE3 inverse() const { return {R.transpose(), -(R.transpose() * p)}; }

  Vec6 actMotion(const Vec6& m) const {
    const Vec3 w = R * m.tail<3>();
    return stack(R * m.head<3>() + p.cross(w), w);
  }
  Vec6 actInvMotion(const Vec6& m) const {
    return stack(R.transpose() * (m.head<3>() - p.cross(m.tail<3>())), R.transpose() * m.tail<3>());
  }
  Vec6 actForce(const Vec6& f) const {
    const Vec3 fl = R * f.head<3>();
    return stack(fl, R * f.tail<3>() + p.cross(fl));
  }
  Vec6 actInvForce(const Vec6& f) const {
    return stack(R.transpose() * f.head<3>(), R.transpose() * (f.tail<3>() - p.cross(f.head<3>())));
  }
  /// A 6x6 spatial inertia (symmetric) given in B coordinates, expressed in A:
  /// X^T I X with X = motionMatrixInv(), computed by 3x3 blocks (rotate, then
  /// shift by p) at about half the cost of the two 6x6 products.
  Mat6 actInertia(const Mat6& I) const {
    const Mat3 A = R * I.topLeftCorner<3, 3>() * R.transpose();
    const Mat3 B = R * I.topRightCorner<3, 3>() * R.transpose();
    const Mat3 C = R * I.bottomRightCorner<3, 3>() * R.transpose();
    const Mat3 P = skew(p);
    const Mat3 top = B - A * P;  // A P^T + B, with P^T = -P
    const Mat3 PB = P * B;
    Mat6 out;
    out.topLeftCorner<3, 3>() = A;
    out.topRightCorner<3, 3>() = top;
    out.bottomLeftCorner<3, 3>() = top.transpose();
    out.bottomRightCorner<3, 3>() = C + PB + PB.transpose() - P * A * P;
    return out;
  }
  /// 6x6 matrix of actMotion (maps B motion coordinates to A).
  Mat6 motionMatrix() const {
    Mat6 X = Mat6::Zero();
    X.topLeftCorner<3, 3>() = R;
    X.topRightCorner<3, 3>() = skew(p) * R;
    X.bottomRightCorner<3, 3>() = R;
    return X;
  }
  /// 6x6 matrix of actInvMotion (Featherstone's X_{B<-A}); its transpose is actForce.
  Mat6 motionMatrixInv() const { return inverse().motionMatrix(); }
};

/// Rotation matrix from URDF roll-pitch-yaw (fixed axes X, then Y, then Z).
inline Mat3 rpyToMatrix(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

/// A rotation read from a file (a URDF origin, a layout's offset or target),
/// snapped when it is read, so the generic and the generated solvers see the
/// same numbers and the generator can fold them. Entries within a few ulps of
/// 0 or +-1 are what an rpy of pi/2 in decimal leaves behind
/// (cos(1.5707963267948966) = 6.1e-17): the entries of a rotation are bounded
/// by 1, so the absolute threshold 1e-15 (4.5 eps) is a relative one, the
/// round-off of a product of three elementary rotations is a few eps, and no
/// rotation a file means differs from an exact 0 or +-1 by less.
///
/// A whole rotation within kQuarterTurnTolerance of a signed permutation (every
/// entry that close to 0 or +-1) is that permutation: the quarter turns
/// exporters write as 1.57079632679 or 3.14159265359 (11-12 digits of pi/2 and
/// pi: 4.9e-12 and 2.1e-12 off) leave entries of 1e-12 that no entry-wise
/// threshold of a few ulps catches, and each costs live operations in every
/// generated function (Talos: 4 % of constrained_aba's, docs/emitter.md,
/// "Quarter turns"). The snapped matrix is a rotation exactly (a signed
/// permutation with the determinant of R, +1); it is at most 1e-10 rad from
/// the file's, far below the 1e-9 to which the solvers agree with Pinocchio on
/// the file's numbers. A rotation that mixes a quarter turn with another angle
/// keeps its entries (snapping some of them would leave a matrix that is not a
/// rotation).
inline constexpr double kQuarterTurnTolerance = 1e-10;

inline Mat3 snapRotation(Mat3 R) {
  Mat3 P;
  bool permutation = true;
  for (int k = 0; k < 9; ++k) {
    const double x = R.data()[k], nearest = std::round(x);  // |x| <= 1: -1, 0 or 1
    P.data()[k] = nearest == 0.0 ? 0.0 : nearest;  // no -0.0
    permutation = permutation && std::abs(x - nearest) < kQuarterTurnTolerance;
  }
  if (permutation) return P;
  for (int k = 0; k < 9; ++k) {
    double& x = R.data()[k];
    if (std::abs(x) < 1e-15) x = 0.0;
    else if (std::abs(x - 1.0) < 1e-15) x = 1.0;
    else if (std::abs(x + 1.0) < 1e-15) x = -1.0;
  }
  return R;
}

/// Rotation by angle q about a unit axis a (Rodrigues), exact for axis-aligned a.
inline Mat3 axisAngle(const Vec3& a, double q) {
  const double c = std::cos(q), s = std::sin(q), t = 1.0 - c;
  Mat3 R;
  R << t * a.x() * a.x() + c, t * a.x() * a.y() - s * a.z(), t * a.x() * a.z() + s * a.y(),
      t * a.x() * a.y() + s * a.z(), t * a.y() * a.y() + c, t * a.y() * a.z() - s * a.x(),
      t * a.x() * a.z() - s * a.y(), t * a.y() * a.z() + s * a.x(), t * a.z() * a.z() + c;
  return R;
}

/// Rigid-body inertia: mass, centre of mass and rotational inertia about the COM,
/// all in the body frame.
struct Inertia {
  double mass = 0.0;
  Vec3 com = Vec3::Zero();
  Mat3 Ic = Mat3::Zero();

  /// 6x6 spatial inertia about the body origin, [linear; angular] order.
  Mat6 matrix() const {
    Mat6 I;
    const Mat3 C = skew(com);
    I.topLeftCorner<3, 3>() = mass * Mat3::Identity();
    I.topRightCorner<3, 3>() = -mass * C;
    I.bottomLeftCorner<3, 3>() = mass * C;
    I.bottomRightCorner<3, 3>() = Ic - mass * C * C;
    return I;
  }
  /// The same body seen from a frame A, given the placement of the body frame in A.
  Inertia transformed(const SE3& A_M_body) const {
    return {mass, A_M_body.R * com + A_M_body.p, A_M_body.R * Ic * A_M_body.R.transpose()};
  }
  /// Sum of two inertias expressed in the same frame (parallel-axis theorem).
  Inertia operator+(const Inertia& o) const {
    const double m = mass + o.mass;
    if (m == 0.0) return {0.0, Vec3::Zero(), Ic + o.Ic};
    const Vec3 c = (mass * com + o.mass * o.com) / m;
    const Vec3 d1 = com - c, d2 = o.com - c;
    const Mat3 shift1 = mass * (d1.squaredNorm() * Mat3::Identity() - d1 * d1.transpose());
    const Mat3 shift2 = o.mass * (d2.squaredNorm() * Mat3::Identity() - d2 * d2.transpose());
    return {m, c, Ic + shift1 + o.Ic + shift2};
  }
};

}  // namespace proxgen

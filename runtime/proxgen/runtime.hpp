// The runtime of the solvers proxgen generates: the little they call that is
// not straight-line arithmetic. Header-only, fixed size, no heap, no
// exceptions, no RTTI, nothing but <cmath>; templated on the solver's Scalar.
//
// The generated code prints every product itself (constants folded at
// generation time), so what is left here is the sine and cosine of the joint
// angles, the SE(3) logarithm that a Baumgarte position gain on a 6D
// constraint needs, and three selects (the quaternion's scale, the warm start,
// the residual's largest row).
#pragma once

#include <cmath>

// The generated files split their straight-line code into functions of a few
// bodies each; kept out of line, they keep the compiler's time linear in the
// robot's size (a call costs a few instructions per part).
// Their parameters (the workspace, q, v, tau) never overlap: saying so spares
// the compiler the aliasing analysis (and some reloads).
#if defined(__GNUC__) || defined(__clang__)
#define PROXGEN_RT_NOINLINE __attribute__((noinline))
#define PROXGEN_RT_RESTRICT __restrict__
#elif defined(_MSC_VER)
#define PROXGEN_RT_NOINLINE __declspec(noinline)
#define PROXGEN_RT_RESTRICT __restrict
#else
#define PROXGEN_RT_NOINLINE
#define PROXGEN_RT_RESTRICT
#endif
// The derivatives' dense loops (fixed bounds): their inner loop unrolled, so a
// multiply-add costs its arithmetic and not the loop's counter and branch
// (docs/derivatives.md, "Dense products").
// The generated column loops (one loop over the columns that share a body's
// arithmetic) kept as loops: GCC peels a short loop with a constant trip count
// completely, and on a large robot that code, run once per call, is fetched
// anew each time (Talos' mass_matrix: 0.90 of the time, 9 % less code; never
// slower on the shared cases, docs/benchmarks.md).
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 8)
#define PROXGEN_RT_UNROLL _Pragma("GCC unroll 16")
#define PROXGEN_RT_NO_UNROLL _Pragma("GCC unroll 1")
#else
#define PROXGEN_RT_UNROLL
#define PROXGEN_RT_NO_UNROLL
#endif

namespace proxgen_rt {

// The runtime's version: a generated source checks it against the proxgen
// that printed it (static_assert), so a solver is never compiled against a
// runtime whose helpers may differ. PROXGEN_RT_VERSION_* for preprocessor use.
#define PROXGEN_RT_VERSION_MAJOR 0
#define PROXGEN_RT_VERSION_MINOR 1
inline constexpr int version_major = PROXGEN_RT_VERSION_MAJOR, version_minor = PROXGEN_RT_VERSION_MINOR;

/// max(|a|, |b|, |c|, |d|), branch-free (compare-and-select: maxsd on x86):
/// the free-flyer quaternion is divided by it before it is normalised, as
/// `proxgen eval` does, so that no squared norm overflows or underflows. A
/// NaN component is not propagated here; it reaches the outputs through the
/// division that follows.
template <class S>
inline S largest_magnitude(S a, S b, S c, S d) noexcept {
  const S x = std::fabs(a), y = std::fabs(b), z = std::fabs(c), t = std::fabs(d);
  const S xy = x > y ? x : y, zt = z > t ? z : t;
  return xy > zt ? xy : zt;
}

/// The warm start of a solver with N constraint rows: `lambda0` itself, or N
/// zeros when it is null (a pointer select, no branch on the data).
template <int N, class S>
inline const S* initial_multipliers(const S* lambda0) noexcept {
  static constexpr S zeros[N] = {};
  return lambda0 ? lambda0 : zeros;
}

/// max_r |x[r]| over N values; NaN when one of them is NaN or infinite (the
/// sum of x - x is 0 for finite values only), so a failed solve never reads
/// as a small residual.
template <int N, class S>
inline S largest_magnitude_of(const S* x) noexcept {
  S largest = S(0), invalid = S(0);
  for (int r = 0; r < N; ++r) {
    const S a = std::fabs(x[r]);
    largest = a > largest ? a : largest;
    invalid += x[r] - x[r];
  }
  return largest + invalid;
}

/// s = sin(x), c = cos(x). For double: one reduction to r = x - k pi/2,
/// |r| <= pi/4 (pi/2 in three parts, Cody and Waite), the sine and cosine
/// polynomials of fdlibm's kernels on r, and the quadrant k mod 4 picking and
/// signing them, all without branches: joint angles are random to the branch
/// predictor, and the C library's sin and cos cost about twice as many
/// instructions. Within 1.2e-16 (absolute) and 2 ulp of the C library for
/// |x| <= 1e5 (test_runtime.cpp); beyond that, and for NaN and infinities, it
/// calls std::sin and std::cos. Other types call them always.
template <class S>
inline void sincos(S x, S& s, S& c) noexcept {
  s = std::sin(x);
  c = std::cos(x);
}

template <>
inline void sincos<double>(double x, double& s, double& c) noexcept {
  if (!(std::fabs(x) <= 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  // k = round(x 2/pi), |k| < 2^17: k times the first part of pi/2 (33 bits) is
  // exact, and so is x minus it (the two are within a factor 2).
  const int k = int(x * 6.36619772367581382433e-01 + std::copysign(0.5, x));
  const double fk = double(k);
  const double r = ((x - fk * 1.57079632673412561417e+00) - fk * 6.07710050630396597660e-11) -
                   fk * 2.02226624871116645580e-21;
  const double z = r * r;
  const double ps = 8.33333333332248946124e-03 +
                    z * (-1.98412698298579493134e-04 +
                         z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
  const double sr = r + (z * r) * (-1.66666666666666324348e-01 + z * ps);
  const double pc =
      z * (4.16666666666666019037e-02 +
           z * (-1.38888888888741095749e-03 +
                z * (2.48015872894767294178e-05 +
                     z * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
  const double hz = 0.5 * z, w = 1.0 - hz;
  const double cr = w + (((1.0 - w) - hz) + z * pc);  // 1 - z/2 + z^2 pc, the rounding of 1 - z/2 added back
  // Quadrant k mod 4: sin x = sr, cr, -sr, -cr and cos x = cr, -sr, -cr, sr.
  // Table look-ups and multiplications by +-1 are exact and branch-free.
  const double v[2] = {sr, cr};
  const double sign[2] = {1.0, -1.0};
  s = v[k & 1] * sign[(k & 2) >> 1];
  c = v[(k + 1) & 1] * sign[((k + 1) & 2) >> 1];
}

/// sincos called rather than inlined, for the generated code of a robot with
/// many revolute joints: one copy of the kernel instead of one per joint (17 %
/// less code on Talos), where the code's size costs more than the call
/// (docs/benchmarks.md, "sincos called on the larger robots"). The pair comes
/// back by value, in two registers on the common ABIs, not through memory.
template <class S>
struct SinCos {
  S s, c;
};
template <class S>
PROXGEN_RT_NOINLINE SinCos<S> sincos_pair(S x) noexcept {
  SinCos<S> r;
  sincos(x, r.s, r.c);
  return r;
}
template <class S>
inline void sincos_noinline(S x, S& s, S& c) noexcept {
  const SinCos<S> r = sincos_pair(x);
  s = r.s;
  c = r.c;
}

/// Angle and unit axis of a rotation matrix R (row-major), as Eigen's
/// AngleAxis(Quaternion(R)) computes them: the quaternion by Shepperd's method
/// (largest diagonal pivot), then angle = 2 atan2(|vec|, |w|) in [0, pi].
template <class S>
inline void angle_axis(const S* R, S& angle, S* axis) noexcept {
  const S trace = R[0] + R[4] + R[8];
  S q[4];  // x, y, z, w
  if (trace > S(0)) {
    S t = std::sqrt(trace + S(1));
    q[3] = S(0.5) * t;
    t = S(0.5) / t;
    q[0] = (R[7] - R[5]) * t;
    q[1] = (R[2] - R[6]) * t;
    q[2] = (R[3] - R[1]) * t;
  } else {
    int i = 0;
    if (R[4] > R[0]) i = 1;
    if (R[8] > R[4 * i]) i = 2;
    const int j = (i + 1) % 3, k = (j + 1) % 3;
    S t = std::sqrt(R[4 * i] - R[4 * j] - R[4 * k] + S(1));
    q[i] = S(0.5) * t;
    t = S(0.5) / t;
    q[3] = (R[3 * k + j] - R[3 * j + k]) * t;
    q[j] = (R[3 * j + i] + R[3 * i + j]) * t;
    q[k] = (R[3 * k + i] + R[3 * i + k]) * t;
  }
  S n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  if (n == S(0)) {
    angle = S(0);
    axis[0] = S(1);
    axis[1] = S(0);
    axis[2] = S(0);
    return;
  }
  angle = S(2) * std::atan2(n, std::fabs(q[3]));
  if (q[3] < S(0)) n = -n;
  for (int c = 0; c < 3; ++c) axis[c] = q[c] / n;
}

/// log of the placement {R, p} as a twist [linear; angular]:
/// w = angle * axis, linear = Jl(w)^-1 p (the inverse left Jacobian of SO(3)).
template <class S>
inline void log6(const S* R, const S* p, S* out) noexcept {
  S t, a[3];
  angle_axis(R, t, a);
  const S w[3] = {t * a[0], t * a[1], t * a[2]};
  // Jinv = I - 1/2 [w] + coef [w]^2, coef -> 1/12 as t -> 0.
  const S coef = t > S(1e-6) ? (S(1) - t * std::sin(t) / (S(2) * (S(1) - std::cos(t)))) / (t * t) : S(1) / S(12);
  const S wxp[3] = {w[1] * p[2] - w[2] * p[1], w[2] * p[0] - w[0] * p[2], w[0] * p[1] - w[1] * p[0]};
  const S wxwxp[3] = {w[1] * wxp[2] - w[2] * wxp[1], w[2] * wxp[0] - w[0] * wxp[2], w[0] * wxp[1] - w[1] * wxp[0]};
  for (int c = 0; c < 3; ++c) {
    out[c] = p[c] - S(0.5) * wxp[c] + coef * wxwxp[c];
    out[3 + c] = w[c];
  }
}

}  // namespace proxgen_rt

// W values of one Scalar in the lanes of a vector register, for the batched
// solvers (`proxgen generate --batch W`, docs/batch.md): the solver's
// straight-line code is the same for every state, so it runs on W states at
// once; and for the scalar solvers' sincos_run (below), the joint angles of
// one state many at a time. Header-only, fixed size, no heap, no intrinsics
// headers. Every generated NAME.cpp includes it (and runtime.hpp through it).
//
// With GCC or Clang the lanes are the compilers' vector extension
// (__attribute__((vector_size))): the compiler maps them to SSE2, AVX2,
// AVX-512 or NEON registers as the target allows, and splits a vector wider
// than the target's into several. Any other compiler, or
// PROXGEN_RT_LANES_SCALAR defined, gets a plain array and a loop per
// operation (the same answers; no speed-up).
//
// Every operation is the scalar one lane by lane: +, -, *, / and sqrt are
// IEEE operations, correctly rounded per lane; the selects and the sign
// operations are bit operations; sincos runs the scalar kernel's operations in
// the same order (and the C library beyond its range, per lane); the SE(3)
// logarithm runs the scalar function on each lane. So each lane of a batched
// solver computes what the scalar solver computes on that state, operation for
// operation (docs/batch.md, "Lane by lane").
#pragma once

#include <cstring>
#include <type_traits>

#include "runtime.hpp"  // beside this file

#if !defined(PROXGEN_RT_LANES_SCALAR) && (defined(__GNUC__) || defined(__clang__))
#define PROXGEN_RT_LANES_VECTOR 1
#else
#define PROXGEN_RT_LANES_VECTOR 0
#endif

// The bytes of the target's widest vector register the runtime's kernels
// use (sincos_run, row_madd below): 64 with AVX-512, 32 with AVX, 16 with
// SSE2 or NEON, 0 without vector lanes.
#if PROXGEN_RT_LANES_VECTOR && defined(__AVX512F__)
#define PROXGEN_RT_VECTOR_BYTES 64
#elif PROXGEN_RT_LANES_VECTOR && defined(__AVX__)
#define PROXGEN_RT_VECTOR_BYTES 32
#elif PROXGEN_RT_LANES_VECTOR && (defined(__SSE2__) || defined(__ARM_NEON))
#define PROXGEN_RT_VECTOR_BYTES 16
#else
#define PROXGEN_RT_VECTOR_BYTES 0
#endif

namespace proxgen_rt {

namespace lanes_detail {
template <class S>
struct bits;  // the signed integer of S's size: the lanes of a mask
template <>
struct bits<double> {
  using type = long long;
};
template <>
struct bits<float> {
  using type = int;
};
}  // namespace lanes_detail

template <class S, int W>
struct lanes;

/// The result of a lane-wise comparison: per lane all ones (true) or zero.
template <class S, int W>
struct lanes_mask {
  using I = typename lanes_detail::bits<S>::type;
#if PROXGEN_RT_LANES_VECTOR
  typedef I ivec __attribute__((vector_size(sizeof(S) * W)));
  ivec m;
  bool operator[](int l) const noexcept { return m[l] != 0; }
#else
  I m[W];
  bool operator[](int l) const noexcept { return m[l] != 0; }
#endif
  friend lanes_mask operator&(const lanes_mask& a, const lanes_mask& b) noexcept {
    lanes_mask r;
#if PROXGEN_RT_LANES_VECTOR
    r.m = a.m & b.m;
#else
    for (int l = 0; l < W; ++l) r.m[l] = a.m[l] & b.m[l];
#endif
    return r;
  }
  friend lanes_mask operator|(const lanes_mask& a, const lanes_mask& b) noexcept {
    lanes_mask r;
#if PROXGEN_RT_LANES_VECTOR
    r.m = a.m | b.m;
#else
    for (int l = 0; l < W; ++l) r.m[l] = a.m[l] | b.m[l];
#endif
    return r;
  }
  friend lanes_mask operator!(const lanes_mask& a) noexcept {
    lanes_mask r;
#if PROXGEN_RT_LANES_VECTOR
    r.m = ~a.m;
#else
    for (int l = 0; l < W; ++l) r.m[l] = ~a.m[l];
#endif
    return r;
  }
};

/// True when some lane of m is.
template <class S, int W>
inline bool any(const lanes_mask<S, W>& m) noexcept {
  bool r = false;
  for (int l = 0; l < W; ++l) r = r || m[l];
  return r;
}

template <class S, int W>
struct lanes {
  static_assert(W == 2 || W == 4 || W == 8 || W == 16, "proxgen_rt::lanes: W is 2, 4, 8 or 16");
  using scalar = S;
  using mask = lanes_mask<S, W>;
  using I = typename lanes_detail::bits<S>::type;
  static constexpr int width = W;
#if PROXGEN_RT_LANES_VECTOR
  typedef S vec __attribute__((vector_size(sizeof(S) * W)));
  typedef I ivec __attribute__((vector_size(sizeof(S) * W)));
  vec x;
#else
  alignas(sizeof(S) * W) S x[W];
#endif

  lanes() = default;  // uninitialised, as a double is; lanes{} is zero
  // Every lane s: implicit, so the printed literals and the settings' scalars
  // enter lane-wise arithmetic as they enter the scalar solver's.
  lanes(S s) noexcept {  // NOLINT(google-explicit-constructor)
#if PROXGEN_RT_LANES_VECTOR
    x = s - vec{};  // s - (+0) is s for every s (-0 and NaN included)
#else
    for (int l = 0; l < W; ++l) x[l] = s;
#endif
  }

  S operator[](int l) const noexcept { return x[l]; }
  void set(int l, S s) noexcept { x[l] = s; }
  /// W consecutive scalars (no alignment needed), and back.
  static lanes load(const S* p) noexcept {
    lanes r;
    std::memcpy(&r.x, p, sizeof r.x);
    return r;
  }
  void store(S* p) const noexcept { std::memcpy(p, &x, sizeof x); }

#if PROXGEN_RT_LANES_VECTOR
#define PROXGEN_RT_LANES_OP(op)                              \
  friend lanes operator op(const lanes& a, const lanes& b) noexcept {      \
    lanes r;                                                 \
    r.x = a.x op b.x;                                        \
    return r;                                                \
  }                                                          \
  lanes& operator op##=(const lanes& b) noexcept {                  \
    x = x op b.x;                                            \
    return *this;                                            \
  }
#define PROXGEN_RT_LANES_CMP(op)                             \
  friend mask operator op(const lanes& a, const lanes& b) noexcept {       \
    mask r;                                                  \
    r.m = (ivec)(a.x op b.x);                                \
    return r;                                                \
  }
#else
#define PROXGEN_RT_LANES_OP(op)                              \
  friend lanes operator op(const lanes& a, const lanes& b) noexcept {      \
    lanes r;                                                 \
    for (int l = 0; l < W; ++l) r.x[l] = a.x[l] op b.x[l];   \
    return r;                                                \
  }                                                          \
  lanes& operator op##=(const lanes& b) noexcept {                  \
    for (int l = 0; l < W; ++l) x[l] = x[l] op b.x[l];       \
    return *this;                                            \
  }
#define PROXGEN_RT_LANES_CMP(op)                             \
  friend mask operator op(const lanes& a, const lanes& b) noexcept {       \
    mask r;                                                  \
    for (int l = 0; l < W; ++l) r.m[l] = a.x[l] op b.x[l] ? I(-1) : I(0); \
    return r;                                                \
  }
#endif
  PROXGEN_RT_LANES_OP(+)
  PROXGEN_RT_LANES_OP(-)
  PROXGEN_RT_LANES_OP(*)
  PROXGEN_RT_LANES_OP(/)
  PROXGEN_RT_LANES_CMP(<)
  PROXGEN_RT_LANES_CMP(<=)
  PROXGEN_RT_LANES_CMP(>)
  PROXGEN_RT_LANES_CMP(>=)
  PROXGEN_RT_LANES_CMP(==)
  PROXGEN_RT_LANES_CMP(!=)
#undef PROXGEN_RT_LANES_OP
#undef PROXGEN_RT_LANES_CMP

  friend lanes operator-(const lanes& a) noexcept {
    lanes r;
#if PROXGEN_RT_LANES_VECTOR
    r.x = -a.x;
#else
    for (int l = 0; l < W; ++l) r.x[l] = -a.x[l];
#endif
    return r;
  }
  friend lanes operator+(const lanes& a) noexcept { return a; }
};

/// Per lane: m ? a : b (bit for bit the lane of a or of b).
template <class S, int W>
inline lanes<S, W> select(const lanes_mask<S, W>& m, const lanes<S, W>& a, const lanes<S, W>& b) noexcept {
  lanes<S, W> r;
#if PROXGEN_RT_LANES_VECTOR
  using V = typename lanes<S, W>::vec;
  using IV = typename lanes<S, W>::ivec;
  r.x = (V)((m.m & (IV)a.x) | (~m.m & (IV)b.x));
#else
  for (int l = 0; l < W; ++l) r.x[l] = m[l] ? a.x[l] : b.x[l];
#endif
  return r;
}

/// |a| per lane (the sign bit cleared, as std::fabs does, NaN included).
template <class S, int W>
inline lanes<S, W> fabs(const lanes<S, W>& a) noexcept {
  lanes<S, W> r;
#if PROXGEN_RT_LANES_VECTOR
  using V = typename lanes<S, W>::vec;
  using IV = typename lanes<S, W>::ivec;
  const IV sign = (IV)(-lanes<S, W>(S(0)).x);  // the sign bit alone
  r.x = (V)((IV)a.x & ~sign);
#else
  for (int l = 0; l < W; ++l) r.x[l] = std::fabs(a.x[l]);
#endif
  return r;
}

/// |magnitude| with the sign of `sign`, per lane (std::copysign).
template <class S, int W>
inline lanes<S, W> copysign(const lanes<S, W>& magnitude, const lanes<S, W>& sign) noexcept {
  lanes<S, W> r;
#if PROXGEN_RT_LANES_VECTOR
  using V = typename lanes<S, W>::vec;
  using IV = typename lanes<S, W>::ivec;
  const IV bit = (IV)(-lanes<S, W>(S(0)).x);
  r.x = (V)(((IV)magnitude.x & ~bit) | ((IV)sign.x & bit));
#else
  for (int l = 0; l < W; ++l) r.x[l] = std::copysign(magnitude.x[l], sign.x[l]);
#endif
  return r;
}

/// Square root per lane (IEEE, correctly rounded: std::sqrt's answer).
template <class S, int W>
inline lanes<S, W> sqrt(const lanes<S, W>& a) noexcept {
  lanes<S, W> r;
  for (int l = 0; l < W; ++l) r.x[l] = std::sqrt(a.x[l]);
  return r;
}

// ---- Blocks in pairs (the scalar solvers' shared kernels, docs/emitter.md).
//
// Two bodies whose blocks are the same code (a left and a right leg) run as
// one: each value the block reads is gathered from the two bodies' members
// into the two lanes of a pair, each value it stores is scattered back. The
// arithmetic between is the scalar block's, lane by lane.

/// The pair (a, b).
template <class S>
inline lanes<S, 2> gather2(S a, S b) noexcept {
  lanes<S, 2> r;
#if PROXGEN_RT_LANES_VECTOR
  r.x = typename lanes<S, 2>::vec{a, b};
#else
  r.x[0] = a, r.x[1] = b;
#endif
  return r;
}

/// a = x[0], b = x[1]. Called as scatter2<Scalar>(...), so that a scalar
/// expression (a constant the block stores) enters as the pair of it.
template <class S>
inline void scatter2(const lanes<S, 2>& x, S& a, S& b) noexcept {
  a = x.x[0];
  b = x.x[1];
}

/// x with each lane's sign turned where that lane's sign is -1: `sign` holds
/// +1 or -1 per lane (a pair of the table). Two mirrored blocks (a left and a
/// right arm about negated axes) print the same code but for signs; where they
/// differ, the pair turns one lane: `a - x` in one block and `a + x` in the
/// other run as `a + flip(s, x)`. Exact: a product with +-1 only turns the sign
/// bit, so each lane's value is its block's bit for bit (of a NaN, whose sign
/// IEEE 754 leaves to the operation, that it is a NaN).
template <class S, int W>
inline lanes<S, W> flip(const lanes<S, W>& sign, const lanes<S, W>& x) noexcept {
  return sign * x;
}

/// Pair i of a table of pairs {a0, b0, a1, b1, ...}: the two blocks'
/// constants. The table is aligned to a pair (alignas(2 * sizeof(S))), so the
/// pair is one aligned load, which the compiler folds into the operation that
/// uses it (a literal pair would be loaded and duplicated: two instructions).
template <class S>
inline lanes<S, 2> pair_at(const S* table, int i) noexcept {
  lanes<S, 2> r;
#if PROXGEN_RT_LANES_VECTOR
  std::memcpy(&r.x, __builtin_assume_aligned(table + 2 * i, 2 * sizeof(S)), sizeof r.x);
#else
  r.x[0] = table[2 * i], r.x[1] = table[2 * i + 1];
#endif
  return r;
}

/// largest_magnitude (runtime.hpp) per lane: the same compares and selects.
template <class S, int W>
inline lanes<S, W> largest_magnitude(const lanes<S, W>& a, const lanes<S, W>& b, const lanes<S, W>& c,
                                     const lanes<S, W>& d) noexcept {
  const lanes<S, W> x = fabs(a), y = fabs(b), z = fabs(c), t = fabs(d);
  const lanes<S, W> xy = select(x > y, x, y), zt = select(z > t, z, t);
  return select(xy > zt, xy, zt);
}

/// initial_multipliers (runtime.hpp) over lanes: the warm start, or N zero lanes.
template <int N, class S, int W>
inline const lanes<S, W>* initial_multipliers(const lanes<S, W>* lambda0) noexcept {
  static const lanes<S, W> zeros[N] = {};
  return lambda0 ? lambda0 : zeros;
}

/// largest_magnitude_of (runtime.hpp) per lane: NaN in a lane with a NaN or
/// infinite value.
template <int N, class S, int W>
inline lanes<S, W> largest_magnitude_of(const lanes<S, W>* x) noexcept {
  lanes<S, W> largest(S(0)), invalid(S(0));
  for (int r = 0; r < N; ++r) {
    const lanes<S, W> a = fabs(x[r]);
    largest = select(a > largest, a, largest);
    invalid += x[r] - x[r];
  }
  return largest + invalid;
}

/// sincos (runtime.hpp) per lane. Float: the C library per lane, as the
/// scalar function. Double: the scalar kernel's operations in the same order
/// on all lanes at once; the lanes past its range (|x| > 1e5, NaN, infinite)
/// run it on 0 and then take the C library's answer, lane by lane.
template <class S, int W>
inline void sincos(const lanes<S, W>& x, lanes<S, W>& s, lanes<S, W>& c) noexcept {
  for (int l = 0; l < W; ++l) {
    S sl, cl;
    sincos(x[l], sl, cl);
    s.set(l, sl);
    c.set(l, cl);
  }
}

#if PROXGEN_RT_LANES_VECTOR
template <int W>
inline void sincos(const lanes<double, W>& x_in, lanes<double, W>& s, lanes<double, W>& c) noexcept {
  using L = lanes<double, W>;
  const L x = x_in;  // read after s and c are written
  using IV = typename L::ivec;
  const typename L::mask inside = fabs(x) <= L(1e5);  // false for NaN and infinities
  const L xr = select(inside, x, L(0.0));  // no lane converts an out-of-range value to an integer
  // The scalar kernel, operation for operation (runtime.hpp: int(...) truncates, as the conversion here).
  const L kx = xr * L(6.36619772367581382433e-01) + copysign(L(0.5), xr);
  L fk;
#if defined(__AVX512F__)
  const IV k = __builtin_convertvector(kx.x, IV);  // vcvttpd2qq
  fk.x = __builtin_convertvector(k, typename L::vec);
#else
  // k in 32-bit lanes (|k| < 2^17): SSE2 and AVX convert doubles to them in one
  // instruction (cvttpd2dq, and back cvtdq2pd), to 64-bit lanes one by one.
  typedef int K32 __attribute__((vector_size(4 * W)));
  const K32 k32 = __builtin_convertvector(kx.x, K32);
  fk.x = __builtin_convertvector(k32, typename L::vec);
  const IV k = __builtin_convertvector(k32, IV);
#endif
  const L r = ((xr - fk * L(1.57079632673412561417e+00)) - fk * L(6.07710050630396597660e-11)) -
              fk * L(2.02226624871116645580e-21);
  const L z = r * r;
  const L ps = L(8.33333333332248946124e-03) +
               z * (L(-1.98412698298579493134e-04) +
                    z * (L(2.75573137070700676789e-06) +
                         z * (L(-2.50507602534068634195e-08) + z * L(1.58969099521155010221e-10))));
  const L sr = r + (z * r) * (L(-1.66666666666666324348e-01) + z * ps);
  const L pc =
      z * (L(4.16666666666666019037e-02) +
           z * (L(-1.38888888888741095749e-03) +
                z * (L(2.48015872894767294178e-05) +
                     z * (L(-2.75573143513906633035e-07) +
                          z * (L(2.08757232129817482790e-09) + z * L(-1.13596475577881948265e-11))))));
  const L hz = L(0.5) * z, w = L(1.0) - hz;
  const L cr = w + (((L(1.0) - w) - hz) + z * pc);
  // Quadrant k mod 4, as the scalar table look-ups: sin = sr, cr, -sr, -cr; cos = cr, -sr, -cr, sr.
  const IV k1 = k + 1;
#if defined(__AVX512F__)
  // Comparisons into mask registers and blends.
  const IV zero = IV{};
  typename L::mask odd, neg, odd1, neg1;
  odd.m = (k & 1) != zero;
  neg.m = (k & 2) != zero;
  odd1.m = (k1 & 1) != zero;
  neg1.m = (k1 & 2) != zero;
  s = select(odd, cr, sr) * select(neg, L(-1.0), L(1.0));
  c = select(odd1, cr, sr) * select(neg1, L(-1.0), L(1.0));
#else
  // In bit operations, without a comparison (SSE2 has no 64-bit one, and GCC
  // picked lane by lane through general registers: 60 of the 140 instructions
  // of a window of two): `odd` all ones where k is odd (0 - (k & 1)), and the
  // sign bit flipped where k & 2 is set, the same bits as the multiplication
  // by -1 (the values are finite; -1 * 0 is -0 either way).
  using V = typename L::vec;
  const IV sign = (IV)(-L(0.0)).x;  // the sign bit alone
  const IV odd = -(k & 1), odd1 = -(k1 & 1);
  const IV flip = -(k & 2) & sign, flip1 = -(k1 & 2) & sign;  // -2 has the sign bit set
  s.x = (V)((((IV)cr.x & odd) | ((IV)sr.x & ~odd)) ^ flip);
  c.x = (V)((((IV)cr.x & odd1) | ((IV)sr.x & ~odd1)) ^ flip1);
#endif
  if (any(!inside)) {
    for (int l = 0; l < W; ++l) {
      if (inside[l]) continue;
      s.set(l, std::sin(x[l]));
      c.set(l, std::cos(x[l]));
    }
  }
}
#endif

// ---- The joint angles' sines and cosines of a scalar solver, many per call.
//
// A scalar solver computes each revolute joint's sine and cosine where its
// body's step needs them: inline (sincos_joint, robots of 4 revolute joints
// or fewer) or through a call of the runtime's kernel (sincos_joint_called,
// larger robots: the generator's sincosCalled). Where the target's vector registers pay, one call before
// the kinematics computes a run of consecutive joint angles in the lanes
// instead (sincos_run<N> before inline joints, sincos_run<N, true> before
// called ones), and each joint's call is empty:
// - four or more double lanes (AVX: 4, AVX-512: 8), both forms: with
//   AVX-512 Talos' solvers take 0.88-0.92 of the time and its
//   inverse_dynamics 0.68;
// - two lanes (x86-64's SSE2), before called joints only: a call in the
//   middle of a body's block spills the live values around it (every xmm
//   register is caller-saved), the run in two lanes does not, and computes
//   two angles for about the instructions of one: Talos' inverse_dynamics
//   0.79 of the time, its solvers 0.93-0.94, the Atlas' 0.94-0.99. Before
//   inlined joints the run in two lanes was slower (the iiwa's
//   inverse_dynamics 1.16, Solo's 1.04: the inlined kernel's latency hides
//   behind the body's arithmetic), so there each joint computes its own
//   (and the generator inlines only on robots of four joints or fewer);
// - elsewhere (NEON, not measured; no vector lanes; float and lanes Scalars)
//   the runs are empty and the joints compute.
// docs/benchmarks.md, "sincos in the lanes". Either way every value is the
// scalar kernel's, bit for bit (see sincos above). Define
// PROXGEN_RT_SINCOS_RUN to 0 to keep the joints' calls in both forms, or to
// 1 to take the runs in both forms wherever the target has vector lanes.
//
// The mode is part of the functions' names (an inline namespace), so
// translation units compiled for different targets and linked together never
// pick one another's definitions.
#ifdef PROXGEN_RT_SINCOS_RUN  // the user's choice, for both forms
#define PROXGEN_RT_SINCOS_RUN_CALLED PROXGEN_RT_SINCOS_RUN
#elif PROXGEN_RT_VECTOR_BYTES >= 32
#define PROXGEN_RT_SINCOS_RUN 1
#define PROXGEN_RT_SINCOS_RUN_CALLED 1
#elif PROXGEN_RT_VECTOR_BYTES == 16 && defined(__SSE2__)
#define PROXGEN_RT_SINCOS_RUN 0
#define PROXGEN_RT_SINCOS_RUN_CALLED 1
#else
#define PROXGEN_RT_SINCOS_RUN 0
#define PROXGEN_RT_SINCOS_RUN_CALLED 0
#endif

// The lanes of the run before inlined joints (PROXGEN_RT_SINCOS_RUN_WIDTH)
// and before called ones (..._CALLED_WIDTH); 1: the run is empty.
// (Literals, not VECTOR_BYTES / 8: they are pasted into the namespace's name.)
#if PROXGEN_RT_VECTOR_BYTES == 64
#define PROXGEN_RT_SINCOS_RUN_LANES 8
#elif PROXGEN_RT_VECTOR_BYTES == 32
#define PROXGEN_RT_SINCOS_RUN_LANES 4
#elif PROXGEN_RT_VECTOR_BYTES == 16
#define PROXGEN_RT_SINCOS_RUN_LANES 2
#else
#define PROXGEN_RT_SINCOS_RUN_LANES 1
#endif
#if PROXGEN_RT_SINCOS_RUN
#define PROXGEN_RT_SINCOS_RUN_WIDTH PROXGEN_RT_SINCOS_RUN_LANES
#else
#define PROXGEN_RT_SINCOS_RUN_WIDTH 1
#endif
#if PROXGEN_RT_SINCOS_RUN_CALLED
#define PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH PROXGEN_RT_SINCOS_RUN_LANES
#else
#define PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH 1
#endif
// sincos_run_<inline>_<called>: sincos_run_1_1 (every joint computes its
// own), sincos_run_1_2 (the x86-64 baseline), sincos_run_4_4, sincos_run_8_8.
#define PROXGEN_RT_SINCOS_RUN_NS_(a, b) sincos_run_##a##_##b
#define PROXGEN_RT_SINCOS_RUN_NS_OF(a, b) PROXGEN_RT_SINCOS_RUN_NS_(a, b)
#define PROXGEN_RT_SINCOS_RUN_NS PROXGEN_RT_SINCOS_RUN_NS_OF(PROXGEN_RT_SINCOS_RUN_WIDTH, PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH)

inline namespace PROXGEN_RT_SINCOS_RUN_NS {

/// Whether the run computes Scalar S's sines and cosines before joints that
/// inline sincos (JointsCall false: sincos_joint) or call it (true:
/// sincos_joint_called); else each joint does.
template <class S, bool JointsCall = false>
constexpr bool sincos_in_run() noexcept {
  return (JointsCall ? PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH : PROXGEN_RT_SINCOS_RUN_WIDTH) > 1 &&
         std::is_same<S, double>::value;
}

namespace sincos_run_detail {
// The widest lane count of the run that N values fill: Lanes, halved while
// it exceeds N (1: a single angle, the scalar kernel).
template <int N, int Lanes>
constexpr int width() noexcept {
  int w = Lanes;
  while (w > N) w /= 2;
  return w;
}
template <int W>
inline void window(const double* x, double* s, double* c) noexcept {
  lanes<double, W> sl, cl;
  sincos(lanes<double, W>::load(x), sl, cl);
  sl.store(s);
  cl.store(c);
}

#if PROXGEN_RT_SINCOS_RUN_LANES > 1
// The run's kernel, called: one copy per N.
template <int N>
PROXGEN_RT_NOINLINE void run(const double* x, double* s, double* c) noexcept {
  constexpr int W = width<N, PROXGEN_RT_SINCOS_RUN_LANES>();
  if constexpr (W == 1) {
    sincos(x[0], s[0], c[0]);
  } else {
    for (int i = 0; i + W <= N; i += W) window<W>(x + i, s + i, c + i);
    if constexpr (N % W != 0) window<W>(x + N - W, s + N - W, c + N - W);
  }
}
#endif
}  // namespace sincos_run_detail

/// s[i] = sin x[i], c[i] = cos x[i] for i < N where sincos_in_run<S,
/// JointsCall>(), in windows of W lanes (W = PROXGEN_RT_SINCOS_RUN_LANES,
/// halved while it exceeds N), the last window ending at N (it may overlap the
/// one before: the same values again, never a read past x[N - 1]); else
/// nothing (inline: no call either). JointsCall: the joints after it call
/// sincos_joint_called (true) or sincos_joint (false).
template <int N, bool JointsCall = false, class S>
inline void sincos_run(const S* x, S* s, S* c) noexcept {
#if PROXGEN_RT_SINCOS_RUN_LANES > 1
  if constexpr (sincos_in_run<S, JointsCall>()) sincos_run_detail::run<N>(x, s, c);
#endif
  static_cast<void>(x), static_cast<void>(s), static_cast<void>(c);
}

/// One joint's s = sin x, c = cos x, inline, unless sincos_run<N> computed them.
template <class S>
inline void sincos_joint(S x, S& s, S& c) noexcept {
  if constexpr (!sincos_in_run<S>()) sincos(x, s, c);
  static_cast<void>(x), static_cast<void>(s), static_cast<void>(c);
}

/// The same through a call of the runtime's kernel (sincos_noinline), unless
/// sincos_run<N, true> computed them. (Named for its run since the called form
/// got a run of its own: the name it had before, sincos_joint_noinline, paired
/// with sincos_run<N>, so a source printed before fails to compile here
/// instead of finding both calls empty at the x86-64 baseline.)
template <class S>
inline void sincos_joint_called(S x, S& s, S& c) noexcept {
  if constexpr (!sincos_in_run<S, true>()) sincos_noinline(x, s, c);
  static_cast<void>(x), static_cast<void>(s), static_cast<void>(c);
}

}  // inline namespace PROXGEN_RT_SINCOS_RUN_NS

// ---- One row of a dense product, in the lanes of the target.
//
// The derivative functions' dense products (C += s A B and its sparse forms,
// printed in the generated source) run row by row: C's row plus a sum of B's
// rows. Written as plain loops over the row, GCC unrolls a short row's loop
// completely and the generated code's -fno-tree-slp-vectorize then leaves it
// scalar, with C's row loaded and stored for every k (the iiwa's
// constrained_dynamics_derivatives: 3.3 to 5.3 instructions per multiply-add).
// row_madd holds the row in accumulators of the target's widest lanes (SSE2
// and NEON: 2 doubles, AVX: 4, AVX-512: 8; twice as many floats) across all of
// k, read once and written once, a block of eight accumulators at a time (the
// registers of SSE2), the last block with the fewer than one vector's columns
// left over as scalars in the same pass over k. Each entry adds its terms in
// the order of k, (s a_k) b_k, lane by lane the scalar loop's operations: the
// same bits (tests/runtime/row_madd_checks.inc).
// Other Scalars (a batched solver's lanes, a target without vector registers)
// take the scalar accumulators. The width is part of the names (an inline
// namespace), as for sincos_run above.
#define PROXGEN_RT_ROW_BYTES PROXGEN_RT_VECTOR_BYTES
#if PROXGEN_RT_ROW_BYTES == 64
#define PROXGEN_RT_ROW_NS row_lanes64
#elif PROXGEN_RT_ROW_BYTES == 32
#define PROXGEN_RT_ROW_NS row_lanes32
#elif PROXGEN_RT_ROW_BYTES == 16
#define PROXGEN_RT_ROW_NS row_lanes16
#else
#define PROXGEN_RT_ROW_NS row_scalar
#endif

inline namespace PROXGEN_RT_ROW_NS {
namespace row_detail {

// The widest lanes of S the target holds in a register (1: scalars).
template <class S>
constexpr int width() noexcept {
  constexpr bool real = std::is_same<S, double>::value || std::is_same<S, float>::value;
  return real && PROXGEN_RT_ROW_BYTES >= 2 * int(sizeof(S)) ? PROXGEN_RT_ROW_BYTES / int(sizeof(S)) : 1;
}

constexpr int kBlock = 8;  // accumulators at a time

// c[0, N W + T) += (Add) or = the sum over the ranges of (s a[k as]) b[k ldb,
// + N W + T), in N accumulators of W lanes and T scalars after them, over one
// pass of k. (= starts from zeros, not from c: c's entries just written one by
// one and read back as a vector would stall the store forwarding.)
template <bool Add, class S, int W, int N, int T, int ldb>
inline void block(S* PROXGEN_RT_RESTRICT c, const S* PROXGEN_RT_RESTRICT a, int as,
                  const S* PROXGEN_RT_RESTRICT b, S s, const int* ranges, int nranges) noexcept {
  using L = typename std::conditional<(W > 1), lanes<S, W>, S>::type;  // W = 1: N = 0, no lanes
  L acc[N > 0 ? N : 1];
  S tail[T > 0 ? T : 1];
  if constexpr (N > 0) {
    PROXGEN_RT_UNROLL
    for (int j = 0; j < N; ++j) acc[j] = Add ? L::load(c + j * W) : L(S(0));
  }
  PROXGEN_RT_UNROLL
  for (int j = 0; j < T; ++j) tail[j] = Add ? c[N * W + j] : S(0);
  for (int g = 0; g < nranges; ++g)
    for (int k = ranges[2 * g]; k < ranges[2 * g + 1]; ++k) {
      const S x = s * a[k * as];
      if constexpr (N > 0) {
        const L xl(x);
        PROXGEN_RT_UNROLL
        for (int j = 0; j < N; ++j) acc[j] += xl * L::load(b + k * ldb + j * W);
      }
      PROXGEN_RT_UNROLL
      for (int j = 0; j < T; ++j) tail[j] += x * b[k * ldb + N * W + j];
    }
  if constexpr (N > 0) {
    PROXGEN_RT_UNROLL
    for (int j = 0; j < N; ++j) acc[j].store(c + j * W);
  }
  PROXGEN_RT_UNROLL
  for (int j = 0; j < T; ++j) c[N * W + j] = tail[j];
}

// c[0, p): blocks of kBlock accumulators of W lanes, the last one with the
// fewer than W columns left as scalars (W = 1: kBlock scalars a block).
template <bool Add, class S, int p, int ldb, int W>
inline void row(S* PROXGEN_RT_RESTRICT c, const S* PROXGEN_RT_RESTRICT a, int as, const S* PROXGEN_RT_RESTRICT b,
                S s, const int* ranges, int nranges) noexcept {
  if constexpr (W == 1) {
    if constexpr (p > 0) {
      constexpr int t = p < kBlock ? p : kBlock;
      block<Add, S, 1, 0, t, ldb>(c, a, as, b, s, ranges, nranges);
      row<Add, S, p - t, ldb, 1>(c + t, a, as, b + t, s, ranges, nranges);
    }
  } else if constexpr (p > 0) {
    constexpr int n = p / W < kBlock ? p / W : kBlock;
    constexpr int t = p - n * W < W ? p - n * W : 0;
    block<Add, S, W, n, t, ldb>(c, a, as, b, s, ranges, nranges);
    row<Add, S, p - n * W - t, ldb, W>(c + n * W + t, a, as, b + n * W + t, s, ranges, nranges);
  }
}

}  // namespace row_detail

/// c[0, p) += sum over k in the index ranges [ranges[2 g], ranges[2 g + 1]),
/// g < nranges, in that order, of (s a[k as]) times b[k ldb, + p): one row of
/// C += s A B with A's row (as = 1) or column (as = A's row length) in `a` and
/// B's rows ldb apart. c may not overlap a or b. The same bits as that loop.
template <int p, int ldb, class S>
inline void row_madd(S* PROXGEN_RT_RESTRICT c, const S* PROXGEN_RT_RESTRICT a, int as,
                     const S* PROXGEN_RT_RESTRICT b, S s, const int* ranges, int nranges) noexcept {
  row_detail::row<true, S, p, ldb, row_detail::width<S>()>(c, a, as, b, s, ranges, nranges);
}

/// The same from zeros, c not read: c[0, p) = the sum (a row of C = s A B;
/// the sum starts from +0 as the loop `c = 0; c += ...` does).
template <int p, int ldb, class S>
inline void row_product(S* PROXGEN_RT_RESTRICT c, const S* PROXGEN_RT_RESTRICT a, int as,
                        const S* PROXGEN_RT_RESTRICT b, S s, const int* ranges, int nranges) noexcept {
  row_detail::row<false, S, p, ldb, row_detail::width<S>()>(c, a, as, b, s, ranges, nranges);
}

}  // inline namespace PROXGEN_RT_ROW_NS

/// angle_axis (runtime.hpp) per lane: it branches on the pivot, so each lane
/// runs the scalar function.
template <class S, int W>
inline void angle_axis(const lanes<S, W>* R, lanes<S, W>& angle, lanes<S, W>* axis) noexcept {
  for (int l = 0; l < W; ++l) {
    S Rl[9], al, axl[3];
    for (int i = 0; i < 9; ++i) Rl[i] = R[i][l];
    angle_axis(Rl, al, axl);
    angle.set(l, al);
    for (int i = 0; i < 3; ++i) axis[i].set(l, axl[i]);
  }
}

/// log6 (runtime.hpp) per lane, by the scalar function on each lane.
template <class S, int W>
inline void log6(const lanes<S, W>* R, const lanes<S, W>* p, lanes<S, W>* out) noexcept {
  for (int l = 0; l < W; ++l) {
    S Rl[9], pl[3], ol[6];
    for (int i = 0; i < 9; ++i) Rl[i] = R[i][l];
    for (int i = 0; i < 3; ++i) pl[i] = p[i][l];
    log6(Rl, pl, ol);
    for (int i = 0; i < 6; ++i) out[i].set(l, ol[i]);
  }
}

}  // namespace proxgen_rt

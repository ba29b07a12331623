// The generated solvers' runtime (runtime/proxgen/runtime.hpp): its own sine
// and cosine against the C library's.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "proxgen/runtime.hpp"

namespace {

// Distance in units in the last place of the reference.
double ulps(double value, double reference) {
  const double a = std::fabs(reference);
  return std::fabs(value - reference) / (std::nextafter(a, INFINITY) - a);
}

struct Worst {
  double abs = 0, ulp = 0, at = 0;
  void check(double x) {
    double s = 0, c = 0;
    proxgen_rt::sincos(x, s, c);
    const double e = std::max(std::fabs(s - std::sin(x)), std::fabs(c - std::cos(x)));
    if (e > abs) {
      abs = e;
      at = x;
    }
    ulp = std::max({ulp, ulps(s, std::sin(x)), ulps(c, std::cos(x))});
  }
};

// Both are the correctly rounded value within about half an ulp (glibc's are
// correctly rounded, the polynomials of fdlibm's kernels are within 1 ulp on
// [-pi/4, pi/4], the reduction adds an absolute error of an ulp of r): so
// the two differ by at most eps (1 ulp of values near 1) in absolute terms
// and 2 ulp relative. A wrong quadrant, sign or coefficient shows as an error
// of order 1e-8 or more.
constexpr double kAbs = DBL_EPSILON;
constexpr double kUlps = 2.0;

TEST(Runtime, SinCosMatchesTheCLibraryOverJointAngleRanges) {
  std::mt19937_64 rng(20261126);
  Worst worst;
  for (double range : {1e-6, 1.0, 4.0, 10.0, 100.0, 1e4, 1e5}) {
    std::uniform_real_distribution<double> u(-range, range);
    for (int i = 0; i < 200000; ++i) worst.check(u(rng));
  }
  EXPECT_LE(worst.abs, kAbs) << "at x = " << worst.at;
  EXPECT_LE(worst.ulp, kUlps);
}

// Multiples of pi/2 and their neighbours: the quadrant boundaries, where k
// changes and r is largest (about pi/4 between them) or cancels to nearly 0.
TEST(Runtime, SinCosAtQuadrantBoundaries) {
  Worst worst;
  for (int k = -60000; k <= 60000; k += 7) {
    const double x = k * (M_PI / 2);
    for (double y : {x, std::nextafter(x, -INFINITY), std::nextafter(x, INFINITY), x + M_PI / 4, x - M_PI / 4})
      worst.check(y);
  }
  EXPECT_LE(worst.abs, kAbs) << "at x = " << worst.at;
}

TEST(Runtime, SinCosExactValuesAndTheFallback) {
  double s = 1, c = 0;
  proxgen_rt::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  proxgen_rt::sincos(-0.0, s, c);  // the sign of a zero is not kept (0 * anything adds nothing either way)
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  proxgen_rt::sincos(5e-324, s, c);  // the smallest subnormal: sin x = x
  EXPECT_EQ(s, 5e-324);
  EXPECT_EQ(c, 1.0);
  // Past |x| = 1e5, and for non-finite x, the C library's values themselves.
  for (double x : {1e5 + 0.5, -3.7e7, 1e300}) {
    proxgen_rt::sincos(x, s, c);
    EXPECT_EQ(s, std::sin(x)) << x;
    EXPECT_EQ(c, std::cos(x)) << x;
  }
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (double x : {std::numeric_limits<double>::quiet_NaN(), inf, -inf}) {
    proxgen_rt::sincos(x, s, c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << x;
  }
}

// The called form (the generated code of the larger robots calls it,
// pass_kinematics.cpp) is the inline one bit for bit: the same kernel, its
// pair returned by value. Angles over the joint range, the quadrant
// boundaries, the fallback past 1e5, NaN; double and float.
template <class S>
void expectCalledIsInline(const std::vector<S>& xs) {
  for (S x : xs) {
    S s = 0, c = 0, sc = 0, cc = 0;
    proxgen_rt::sincos(x, s, c);
    proxgen_rt::sincos_noinline(x, sc, cc);
    EXPECT_EQ(std::memcmp(&s, &sc, sizeof(S)), 0) << x;
    EXPECT_EQ(std::memcmp(&c, &cc, sizeof(S)), 0) << x;
  }
}

TEST(Runtime, SinCosCalledIsTheInlineOne) {
  std::vector<double> xs = {0.0, -0.0, 1e-300, 3e5, -1e9, std::numeric_limits<double>::quiet_NaN()};
  for (int k = -8; k <= 8; ++k) xs.push_back(k * 0.7853981633974483);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 1000; ++i) xs.push_back(u(rng));
  expectCalledIsInline(xs);
  expectCalledIsInline(std::vector<float>{0.3f, -2.5f, 1000.0f, 1e6f});
}

TEST(Runtime, SinCosOfFloatIsTheCLibrarys) {
  float s = 0, c = 0;
  for (float x : {0.3f, -2.5f, 1000.0f}) {
    proxgen_rt::sincos(x, s, c);
    EXPECT_EQ(s, std::sin(x));
    EXPECT_EQ(c, std::cos(x));
  }
}

}  // namespace

// The expression printer of the emitter (emit/expr.hpp): exact zeros and ones
// fold away, literals round-trip, products are canonical, unused temporaries
// are not printed, and reading a value after it was overwritten or out of its
// scope is caught at generation time.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "emit/expr.hpp"
#include "model/error.hpp"

namespace proxgen::emit {
namespace {

TEST(Expr, ExactZerosAndOnesFold) {
  CodeBuilder cb(ScalarType::Double);
  const Expr x = cb.input("x"), y = cb.input("y");
  EXPECT_EQ(cb.print(0.0 * x), "0.0");
  EXPECT_EQ(cb.print(1.0 * x), "x");
  EXPECT_EQ(cb.print(x + 0.0), "x");
  EXPECT_EQ(cb.print(x - x), "0.0");
  EXPECT_EQ(cb.print(-1.0 * x), "-x");
  EXPECT_EQ(cb.print(cb.mul(x, 1.0)), "x");
  EXPECT_EQ(cb.print(cb.mul(0.0, y)), "0.0");
  EXPECT_EQ(cb.print(cb.mul(-0.0, y)), "0.0");  // a negative zero is a zero too
  EXPECT_EQ(cb.print(2.0 * x + 3.0 * y - x), "x + 3.0*y");
  EXPECT_EQ(cb.print(0.5 + 2.0 * y), "0.5 + 2.0*y");
  EXPECT_EQ(cb.print(2.0 * x - 2.0 * x + 0.25 * y), "0.25*y");
}

TEST(Expr, ProductsAreCanonical) {
  CodeBuilder cb(ScalarType::Double);
  const Expr x = cb.input("x"), y = cb.input("y");
  // w x v + v x w = 0 exactly (the free flyer's c = v x v) needs x*y == y*x.
  EXPECT_TRUE((cb.mul(x, y) - cb.mul(y, x)).isZero());
  EXPECT_EQ(cb.print(cb.mul(2.0 * x, 3.0 * y)), "6.0*x*y");
  EXPECT_EQ(cb.print(cb.mul(y, -1.0 * x)), "-x*y");
}

TEST(Expr, LiteralsRoundTripInBothScalars) {
  CodeBuilder d(ScalarType::Double), f(ScalarType::Float);
  EXPECT_EQ(d.literal(2), "2.0");
  EXPECT_EQ(d.literal(0.1), "0.1");
  EXPECT_EQ(d.literal(1e-20), "1e-20");
  EXPECT_EQ(f.literal(2), "2.0f");
  EXPECT_EQ(f.literal(0.1), "0.1f");
  EXPECT_EQ(f.literal(-1.5e-20), "-1.5e-20f");
  EXPECT_THROW(f.literal(1e300), Error);  // not representable in float
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> ex(-300, 300);
  for (int n = 0; n < 10000; ++n) {
    const double v = std::ldexp(mant(rng), ex(rng));
    EXPECT_EQ(std::stod(d.literal(v)), v) << d.literal(v);
    const float fv = static_cast<float>(std::ldexp(mant(rng), ex(rng) / 8));
    std::string s = f.literal(fv);
    ASSERT_EQ(s.back(), 'f');
    s.pop_back();
    EXPECT_EQ(std::stof(s), fv) << s;
  }
}

TEST(Expr, SumsBecomeTemporariesBeforeProducts) {
  CodeBuilder cb(ScalarType::Double);
  const Expr x = cb.input("x"), y = cb.input("y"), z = cb.input("z");
  const Expr p = cb.mul(x + y, z);
  cb.store("w.out", p);
  EXPECT_EQ(cb.render(0), "const Scalar t0 = x + y;\nw.out = z*t0;\n");
}

TEST(Expr, UnusedTemporariesAreNotPrinted) {
  CodeBuilder cb(ScalarType::Double);
  const Expr x = cb.input("x"), y = cb.input("y");
  const Expr a = cb.temp(x + y, "a");         // used below
  cb.temp(x - y, "b");                        // never used: dropped
  const Expr c = cb.temp(cb.mul(a, a), "c");  // used by the store
  cb.store("w.out", c + 1.0);
  EXPECT_EQ(cb.render(0), "const Scalar a0 = x + y;\nconst Scalar c0 = a0*a0;\nw.out = 1.0 + c0;\n");
  // The same expression twice is one temporary.
  EXPECT_EQ(cb.print(cb.temp(x + y, "a")), "a0");
}

TEST(Expr, StaleAndOutOfScopeValuesAreCaught) {
  CodeBuilder cb(ScalarType::Double);
  const Expr old = cb.member("w.m[0]");
  cb.store("w.m[0]", old + 1.0);
  EXPECT_THROW(cb.print(old), std::logic_error);  // it would read the new value
  EXPECT_EQ(cb.print(cb.member("w.m[0]")), "w.m[0]");
  cb.open("{");
  const Expr t = cb.temp(cb.mul(cb.input("x"), cb.input("y")));
  cb.close();
  EXPECT_THROW(cb.print(t), std::logic_error);
}

// A swap of two members in place (what a transform that permutes a column's
// entries does): the entry read after the first store is snapshot() into a
// temporary before it, so both stores read the old values; a product of
// members is copied too, a multiple of a temporary is left as it is.
TEST(Expr, SnapshotsKeepValuesAcrossStores) {
  CodeBuilder cb(ScalarType::Double);
  const Expr a = cb.member("w.f[0]"), b = cb.member("w.f[1]");
  const Expr oldA = cb.snapshot(-1.0 * a, "s");
  const Expr oldB = cb.snapshot(b, "s");
  EXPECT_NE(cb.print(oldB), "w.f[1]");
  cb.store("w.f[0]", oldB);
  cb.store("w.f[1]", oldA);
  EXPECT_EQ(cb.render(0), "const Scalar s0 = -w.f[0];\nconst Scalar s1 = w.f[1];\nw.f[0] = s1;\nw.f[1] = s0;\n");
  EXPECT_THROW(cb.print(a), std::logic_error);  // without the snapshot: the new value
  const Expr t = cb.temp(cb.mul(cb.input("x"), cb.input("y")), "t");
  EXPECT_EQ(cb.print(cb.snapshot(2.0 * t)), "2.0*t0");
  const Expr prod = cb.mul(cb.member("w.f[0]"), cb.member("w.f[1]"));
  EXPECT_EQ(cb.print(cb.snapshot(prod, "p")), "p0");
}

TEST(Expr, FloatCodeHasOnlyFloatLiterals) {
  CodeBuilder cb(ScalarType::Float);
  const Expr x = cb.input("x");
  cb.store("w.out", 0.25 * x + 3.0);
  EXPECT_EQ(cb.render(0), "w.out = 3.0f + 0.25f*x;\n");
}

}  // namespace
}  // namespace proxgen::emit

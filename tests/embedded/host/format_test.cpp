// Host check of the firmware's printf-free formatter against glibc's printf("%.*e").
//   g++ -std=c++17 -O2 -I../support/include format_test.cpp ../support/src/format.cpp -o /tmp/format_test
//   /tmp/format_test            # prints "N passed, 0 failed"; exit 0 when all match
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>

#include "fw/format.hpp"

namespace {

int failures = 0;
long checks = 0;

void check_double(double v, int digits) {
  char want[64], got[fw::format_buffer_size];
  std::snprintf(want, sizeof want, "%.*e", digits - 1, v);
  const std::size_t n = fw::format_double(got, v, digits);
  ++checks;
  if (std::strcmp(want, got) != 0 || n != std::strlen(want)) {
    if (++failures < 20) std::printf("double digits=%d: want %s got %s\n", digits, want, got);
  }
}

void check_float(float v, int digits) {
  char want[64], got[fw::format_buffer_size];
  std::snprintf(want, sizeof want, "%.*e", digits - 1, static_cast<double>(v));
  const std::size_t n = fw::format_float(got, v, digits);
  ++checks;
  if (std::strcmp(want, got) != 0 || n != std::strlen(want)) {
    if (++failures < 20) std::printf("float digits=%d: want %s got %s\n", digits, want, got);
  }
}

}  // namespace

int main() {
  const double specials[] = {0.0, -0.0, 1.0, -1.0, 0.1, 0.5, 2.5, 1e300, -1e-300, 123456789.0,
                             DBL_MAX, DBL_MIN, DBL_TRUE_MIN, -DBL_TRUE_MIN, 9.5, 0.95, 99999.5,
                             9.9999999999999999e22, 1e23, 5e-324, 1.7976931348623157e308,
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
  for (double v : specials)
    for (int d = 1; d <= 17; ++d) check_double(v, d);
  const float fspecials[] = {0.0f, -0.0f, 1.0f, 0.1f, FLT_MAX, FLT_MIN, FLT_TRUE_MIN, 16777216.0f,
                             3.4e38f, 1e-45f, std::numeric_limits<float>::infinity()};
  for (float v : fspecials)
    for (int d = 1; d <= 17; ++d) check_float(v, d);

  std::mt19937_64 rng(12345);
  for (int i = 0; i < 200000; ++i) {
    std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isnan(v)) continue;
    check_double(v, 17);
    check_double(v, 1 + static_cast<int>(rng() % 17));
    std::uint32_t fb = static_cast<std::uint32_t>(rng());
    float f;
    std::memcpy(&f, &fb, sizeof f);
    if (std::isnan(f)) continue;
    check_float(f, 9);
    check_float(f, 1 + static_cast<int>(rng() % 17));
  }
  // Values near 1 (typical solver output) and exact halfway cases.
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int i = 0; i < 100000; ++i) {
    check_double(u(rng), 17);
    check_double(std::ldexp(static_cast<double>(rng() % 100000), -static_cast<int>(rng() % 20)),
                 1 + static_cast<int>(rng() % 6));
  }
  char b[fw::format_buffer_size];
  fw::format_double(b, std::nan(""), 17);
  ++checks;
  if (std::strcmp(b, "nan") != 0) ++failures, std::printf("nan: got %s\n", b);
  fw::format_int(b, -9223372036854775807LL - 1);
  ++checks;
  if (std::strcmp(b, "-9223372036854775808") != 0) ++failures, std::printf("int: got %s\n", b);
  fw::format_hex32(b, 0xE000ED88u);
  ++checks;
  if (std::strcmp(b, "0xe000ed88") != 0) ++failures, std::printf("hex: got %s\n", b);

  std::printf("%ld passed, %d failed\n", checks - failures, failures);
  return failures == 0 ? 0 : 1;
}

// Exact, printf-free floating-point formatting (see fw/format.hpp).
//
// A finite binary value is m * 2^e2 with an integer m. Written as N * 10^d10 with an integer N
// (N = m << e2, d10 = 0 when e2 >= 0; N = m * 5^-e2, d10 = e2 when e2 < 0), its decimal digits
// are those of the big integer N, which we get exactly with a small fixed-size bignum (at most
// 2^2547 for a subnormal double: 80 32-bit words). The digits are then rounded half to even at
// the requested precision, as glibc's printf does. Integer arithmetic only, no heap, ~0.8 KB of
// stack, a few thousand 64-bit divisions per number: meant for test output, not for hot loops.
#include "fw/format.hpp"

#include <cstring>

namespace {

constexpr int kMaxWords = 82;   // > 2547 bits
constexpr int kMaxChunks = 88;  // base-1e9 chunks of a number < 10^768
constexpr std::uint32_t kChunk = 1000000000u;
constexpr std::uint32_t kPow10[10] = {1u,      10u,      100u,      1000u,      10000u,
                                      100000u, 1000000u, 10000000u, 100000000u, 1000000000u};

struct BigUint {
  std::uint32_t w[kMaxWords];
  int n = 0;  // words in use; w[n-1] != 0 unless n == 0

  void set(std::uint64_t v) noexcept {
    n = 0;
    while (v != 0) {
      w[n++] = static_cast<std::uint32_t>(v);
      v >>= 32;
    }
  }
  void mul_small(std::uint32_t f) noexcept {
    std::uint64_t carry = 0;
    for (int i = 0; i < n; ++i) {
      const std::uint64_t t = static_cast<std::uint64_t>(w[i]) * f + carry;
      w[i] = static_cast<std::uint32_t>(t);
      carry = t >> 32;
    }
    if (carry != 0) w[n++] = static_cast<std::uint32_t>(carry);
  }
  void shift_left(int bits) noexcept {
    if (n == 0) return;
    const int words = bits / 32;
    const int rem = bits % 32;
    int top = n + words;
    w[top] = 0;
    for (int i = n - 1; i >= 0; --i) {
      const std::uint64_t t = static_cast<std::uint64_t>(w[i]) << rem;
      w[i + words + 1] |= static_cast<std::uint32_t>(t >> 32);
      w[i + words] = static_cast<std::uint32_t>(t);
    }
    for (int i = 0; i < words; ++i) w[i] = 0;
    n = top + 1;
    while (n > 0 && w[n - 1] == 0) --n;
  }
  // Divides in place, returns the remainder.
  std::uint32_t divmod_small(std::uint32_t d) noexcept {
    std::uint64_t rem = 0;
    for (int i = n - 1; i >= 0; --i) {
      const std::uint64_t cur = (rem << 32) | w[i];
      w[i] = static_cast<std::uint32_t>(cur / d);
      rem = cur % d;
    }
    while (n > 0 && w[n - 1] == 0) --n;
    return static_cast<std::uint32_t>(rem);
  }
};

// Decimal digits of N, most significant first, from its base-1e9 chunks (least significant
// first).
struct DecimalDigits {
  std::uint32_t chunk[kMaxChunks];
  int chunks = 0;
  int top_digits = 0;  // digits in chunk[chunks - 1]
  int count = 0;       // total digits

  int digit(int i) const noexcept {  // 0 <= i < count
    if (i < top_digits) return static_cast<int>(chunk[chunks - 1] / kPow10[top_digits - 1 - i] % 10u);
    const int j = i - top_digits;
    const std::uint32_t c = chunk[chunks - 2 - j / 9];
    return static_cast<int>(c / kPow10[8 - j % 9] % 10u);
  }
};

std::size_t put_str(char* buf, std::size_t pos, const char* s) noexcept {
  while (*s != '\0') buf[pos++] = *s++;
  buf[pos] = '\0';
  return pos;
}

// Formats (-1)^neg * m * 2^e2 with `digits` significant digits.
std::size_t format_binary(char* buf, bool neg, std::uint64_t m, int e2, int digits) noexcept {
  if (digits < 1) digits = 1;
  if (digits > 17) digits = 17;
  std::size_t pos = 0;
  if (neg) buf[pos++] = '-';

  int dig[18];
  int exp10 = 0;
  if (m == 0) {
    for (int i = 0; i < digits; ++i) dig[i] = 0;
  } else {
    // Make m odd first: fewer bits to carry around.
    while ((m & 1u) == 0) {
      m >>= 1;
      ++e2;
    }
    BigUint big;
    big.set(m);
    int d10 = 0;
    if (e2 >= 0) {
      big.shift_left(e2);
    } else {
      int k = -e2;
      d10 = e2;
      while (k >= 13) {
        big.mul_small(1220703125u);  // 5^13
        k -= 13;
      }
      std::uint32_t f = 1;
      while (k-- > 0) f *= 5u;
      big.mul_small(f);
    }
    DecimalDigits dd;
    while (big.n > 0) dd.chunk[dd.chunks++] = big.divmod_small(kChunk);
    const std::uint32_t top = dd.chunk[dd.chunks - 1];
    dd.top_digits = 1;
    while (dd.top_digits < 10 && top >= kPow10[dd.top_digits]) ++dd.top_digits;
    dd.count = dd.top_digits + 9 * (dd.chunks - 1);
    exp10 = dd.count - 1 + d10;

    for (int i = 0; i < digits; ++i) dig[i] = i < dd.count ? dd.digit(i) : 0;
    if (dd.count > digits) {
      const int next = dd.digit(digits);
      bool sticky = false;
      for (int i = digits + 1; i < dd.count && !sticky; ++i) sticky = dd.digit(i) != 0;
      const bool up = next > 5 || (next == 5 && (sticky || (dig[digits - 1] & 1) != 0));
      if (up) {
        int i = digits - 1;
        while (i >= 0 && dig[i] == 9) dig[i--] = 0;
        if (i < 0) {
          dig[0] = 1;
          ++exp10;
        } else {
          ++dig[i];
        }
      }
    }
  }

  buf[pos++] = static_cast<char>('0' + dig[0]);
  if (digits > 1) {
    buf[pos++] = '.';
    for (int i = 1; i < digits; ++i) buf[pos++] = static_cast<char>('0' + dig[i]);
  }
  buf[pos++] = 'e';
  buf[pos++] = exp10 < 0 ? '-' : '+';
  const int ae = exp10 < 0 ? -exp10 : exp10;
  if (ae >= 100) buf[pos++] = static_cast<char>('0' + ae / 100);
  buf[pos++] = static_cast<char>('0' + ae / 10 % 10);
  buf[pos++] = static_cast<char>('0' + ae % 10);
  buf[pos] = '\0';
  return pos;
}

}  // namespace

namespace fw {

std::size_t format_double(char* buf, double v, int digits) noexcept {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const bool neg = (bits >> 63) != 0;
  const int biased = static_cast<int>((bits >> 52) & 0x7FFu);
  const std::uint64_t frac = bits & ((std::uint64_t{1} << 52) - 1u);
  if (biased == 0x7FF) {
    std::size_t pos = 0;
    if (neg) buf[pos++] = '-';
    return put_str(buf, pos, frac != 0 ? "nan" : "inf");
  }
  if (biased == 0) return format_binary(buf, neg, frac, -1074, digits);
  return format_binary(buf, neg, frac | (std::uint64_t{1} << 52), biased - 1075, digits);
}

std::size_t format_float(char* buf, float v, int digits) noexcept {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const bool neg = (bits >> 31) != 0;
  const int biased = static_cast<int>((bits >> 23) & 0xFFu);
  const std::uint32_t frac = bits & ((1u << 23) - 1u);
  if (biased == 0xFF) {
    std::size_t pos = 0;
    if (neg) buf[pos++] = '-';
    return put_str(buf, pos, frac != 0 ? "nan" : "inf");
  }
  if (biased == 0) return format_binary(buf, neg, frac, -149, digits);
  return format_binary(buf, neg, frac | (1u << 23), biased - 150, digits);
}

std::size_t format_int(char* buf, long long v) noexcept {
  std::size_t pos = 0;
  unsigned long long u = static_cast<unsigned long long>(v);
  if (v < 0) {
    buf[pos++] = '-';
    u = 0ull - u;
  }
  char tmp[24];
  int n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + static_cast<int>(u % 10u));
    u /= 10u;
  } while (u != 0);
  while (n > 0) buf[pos++] = tmp[--n];
  buf[pos] = '\0';
  return pos;
}

std::size_t format_hex32(char* buf, std::uint32_t v) noexcept {
  static const char kHex[] = "0123456789abcdef";
  buf[0] = '0';
  buf[1] = 'x';
  for (int i = 0; i < 8; ++i) buf[2 + i] = kHex[(v >> (28 - 4 * i)) & 0xFu];
  buf[10] = '\0';
  return 10;
}

}  // namespace fw

// printf-free number formatting for firmware output (no locale, no heap, no libc stdio).
// Floating point output is exact: the digits are those of the binary value, correctly rounded
// (round half to even), byte-identical to glibc's printf("%.*e", digits - 1, value).
#pragma once
#include <cstddef>
#include <cstdint>

namespace fw {

// Enough room for any output of these functions (sign, 17 digits, point, exponent, NUL).
inline constexpr std::size_t format_buffer_size = 32;

// Scientific notation with `digits` significant digits (clamped to 1..17), e.g. digits = 17:
// "-1.2345678901234567e-05"; "inf", "-inf", "nan". 17 digits round-trip any double.
// Returns the length written (without the terminating NUL). buf needs format_buffer_size bytes.
std::size_t format_double(char* buf, double v, int digits = 17) noexcept;

// Same for float; 9 significant digits round-trip any float. Uses no double arithmetic, so it
// costs no soft-float code on a single-precision FPU.
std::size_t format_float(char* buf, float v, int digits = 9) noexcept;

// Decimal integer, e.g. "-42".
std::size_t format_int(char* buf, long long v) noexcept;

// "0x" and 8 hexadecimal digits.
std::size_t format_hex32(char* buf, std::uint32_t v) noexcept;

}  // namespace fw

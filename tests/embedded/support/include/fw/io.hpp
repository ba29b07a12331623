// Small console helpers on top of semihosting and the printf-free formatter.
#pragma once
#include <cstdint>

#include "fw/format.hpp"
#include "fw/semihost.hpp"

namespace fw {

inline void print(const char* s) noexcept { write0(s); }
inline void print_double(double v, int digits = 17) noexcept {
  char b[format_buffer_size];
  format_double(b, v, digits);
  write0(b);
}
inline void print_float(float v, int digits = 9) noexcept {
  char b[format_buffer_size];
  format_float(b, v, digits);
  write0(b);
}
// The natural precision of the scalar: 17 digits for double, 9 for float.
inline void print_scalar(double v) noexcept { print_double(v, 17); }
inline void print_scalar(float v) noexcept { print_float(v, 9); }
inline void print_int(long long v) noexcept {
  char b[format_buffer_size];
  format_int(b, v);
  write0(b);
}
inline void print_hex(std::uint32_t v) noexcept {
  char b[format_buffer_size];
  format_hex32(b, v);
  write0(b);
}

}  // namespace fw

// fw_demo: proves the bare-metal skeleton end to end under qemu. It checks the start-up code
// (.data copied, .bss cleared, a static constructor run, FPU usable), runs 6x6 Cholesky solves
// in the build's scalar type, prints the results through semihosting and exits 0 when they
// match the expected values within a tolerance, 1 otherwise.
#include <cmath>

#include "cholesky6.hpp"
#include "fw/io.hpp"
#include "fw/stack.hpp"
#include "fw/trace.hpp"

namespace {

using demo::n;
using demo::Scalar;

constexpr const char* kScalarName = sizeof(Scalar) == sizeof(double) ? "double" : "float";

// A = L0 L0^T with an integer L0: A and its factor are exact in binary.
constexpr int kL0[n][n] = {{2, 0, 0, 0, 0, 0},  {1, 3, 0, 0, 0, 0},  {-1, 2, 4, 0, 0, 0},
                           {0, 1, -2, 5, 0, 0}, {3, 0, 1, -1, 2, 0}, {1, -1, 0, 2, 1, 3}};
// Case 1: a solution of binary fractions, so b = A x is exact and so is the whole solve.
constexpr Scalar kXExact[n] = {1, -2, Scalar(0.5), 3, Scalar(-1.25), 2};
// Case 2: decimal fractions: b = A x is rounded, the solve shows the scalar's rounding error.
constexpr Scalar kXDecimal[n] = {Scalar(0.1), Scalar(-0.2),  Scalar(0.3),
                                 Scalar(0.7), Scalar(-1.1), Scalar(0.05)};

volatile int g_data_word = 0x12345678;  // .data: must be copied from flash by the reset handler
volatile int g_bss_word;                // .bss: must be zero
int g_ctor_value = 0;

struct StaticInit {  // a static constructor: must have run before main (via __init_array)
  StaticInit() noexcept { g_ctor_value = g_data_word + 1; }
};
StaticInit g_static_init;

Scalar g_A[n * n];  // inputs built at run time, so nothing folds at compile time
Scalar g_b[n];
Scalar g_L[n * n];
Scalar g_x[n];

void print_value(const char* label, Scalar v) {
  fw::print(label);
  fw::print_scalar(v);
  fw::print("\n");
}

// Solves A x = A x_true and checks x (and the factor) against the expected values.
bool run_case(const char* name, const Scalar* x_true, Scalar tol) {
  for (int i = 0; i < n; ++i) {
    Scalar s = 0;
    for (int k = 0; k < n; ++k) s += g_A[i * n + k] * x_true[k];
    g_b[i] = s;
  }
  fw::print("case ");
  fw::print(name);
  fw::print(":\n");
  fw::trace_begin();  // count_insns.py: instructions of one solve
  const bool spd = demo::cholesky_solve(g_A, g_b, g_L, g_x);
  fw::trace_end();
  if (!spd) {
    fw::print("  cholesky_solve: matrix not positive definite\n");
    return false;
  }
  Scalar max_err_x = 0, max_err_l = 0;
  for (int i = 0; i < n; ++i) {
    fw::print("  x[");
    fw::print_int(i);
    fw::print("] = ");
    fw::print_scalar(g_x[i]);
    fw::print("   expected ");
    fw::print_scalar(x_true[i]);
    fw::print("\n");
    const Scalar ex = std::fabs(g_x[i] - x_true[i]);
    if (ex > max_err_x) max_err_x = ex;
    for (int j = 0; j <= i; ++j) {
      const Scalar el = std::fabs(g_L[i * n + j] - static_cast<Scalar>(kL0[i][j]));
      if (el > max_err_l) max_err_l = el;
    }
  }
  Scalar res = 0;  // |A x - b|_inf
  for (int i = 0; i < n; ++i) {
    Scalar s = -g_b[i];
    for (int k = 0; k < n; ++k) s += g_A[i * n + k] * g_x[k];
    if (std::fabs(s) > res) res = std::fabs(s);
  }
  print_value("  max |x - x_true| = ", max_err_x);
  print_value("  max |L - L_true| = ", max_err_l);
  print_value("  |A x - b|_inf    = ", res);
  const bool ok = max_err_x <= tol && max_err_l <= tol;
  fw::print(ok ? "  ok (tolerance " : "  FAILED (tolerance ");
  fw::print_scalar(tol);
  fw::print(")\n");
  return ok;
}

}  // namespace

int main() {
  int failures = 0;
  fw::print("fw_demo: cpu=");
  fw::print(fw::cpu_name());
  fw::print(" scalar=");
  fw::print(kScalarName);
  fw::print("\n");

  if (g_data_word != 0x12345678 || g_bss_word != 0 || g_ctor_value != 0x12345679) {
    fw::print("start-up check FAILED (.data, .bss or static constructor)\n");
    ++failures;
  } else {
    fw::print("start-up: .data copied, .bss zero, static constructor ran\n");
  }

  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      int s = 0;
      for (int k = 0; k < n; ++k) s += kL0[i][k] * kL0[j][k];
      g_A[i * n + j] = static_cast<Scalar>(s);
    }
  }

  // Tolerances: the exact case must be exact; the decimal one within a few hundred ulps.
  const Scalar tol = sizeof(Scalar) == sizeof(double) ? Scalar(1e-12) : Scalar(1e-4f);
  if (!run_case("exact", kXExact, Scalar(0))) ++failures;
  if (!run_case("decimal", kXDecimal, tol)) ++failures;

  if (!fw::report_stack()) ++failures;  // the whole firmware's stack against its budget
  fw::print(failures == 0 ? "fw_demo: PASS\n" : "fw_demo: FAIL\n");
  return failures == 0 ? 0 : 1;
}

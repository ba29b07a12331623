// Demo kernel for the firmware bring-up: a fixed-size 6x6 Cholesky factorisation and solve,
// in the style the generated solvers use (plain arrays, fixed sizes, noexcept, no heap).
#pragma once

#ifndef PROXGEN_DEMO_SCALAR
#define PROXGEN_DEMO_SCALAR double
#endif

namespace demo {

using Scalar = PROXGEN_DEMO_SCALAR;
inline constexpr int n = 6;

// Solves A x = b for a symmetric positive definite A (row-major, n*n; only the lower triangle
// is read). L receives the Cholesky factor (row-major lower triangle, upper part set to 0).
// Returns false, leaving x untouched, if a pivot is not positive.
bool cholesky_solve(const Scalar* A, const Scalar* b, Scalar* L, Scalar* x) noexcept;

}  // namespace demo

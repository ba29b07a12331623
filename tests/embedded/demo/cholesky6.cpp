#include "cholesky6.hpp"

#include <cmath>

namespace demo {

bool cholesky_solve(const Scalar* A, const Scalar* b, Scalar* L, Scalar* x) noexcept {
  for (int i = 0; i < n * n; ++i) L[i] = Scalar(0);
  for (int j = 0; j < n; ++j) {
    Scalar d = A[j * n + j];
    for (int k = 0; k < j; ++k) d -= L[j * n + k] * L[j * n + k];
    if (!(d > Scalar(0))) return false;
    const Scalar ljj = std::sqrt(d);
    L[j * n + j] = ljj;
    const Scalar inv = Scalar(1) / ljj;
    for (int i = j + 1; i < n; ++i) {
      Scalar s = A[i * n + j];
      for (int k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
      L[i * n + j] = s * inv;
    }
  }
  Scalar y[n];
  for (int i = 0; i < n; ++i) {  // L y = b
    Scalar s = b[i];
    for (int k = 0; k < i; ++k) s -= L[i * n + k] * y[k];
    y[i] = s / L[i * n + i];
  }
  for (int i = n - 1; i >= 0; --i) {  // L^T x = y
    Scalar s = y[i];
    for (int k = i + 1; k < n; ++k) s -= L[k * n + i] * x[k];
    x[i] = s / L[i * n + i];
  }
  return true;
}

}  // namespace demo

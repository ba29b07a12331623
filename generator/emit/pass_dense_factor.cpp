// Dense factors and solves, unrolled for a size known at generation time: the
// free flyer's 6 x 6 articulated inertia, the Delassus matrix G + I/mu and the
// Woodbury capacitance I + W^T W. The generic counterpart: Eigen's LLT.
#include "emit/passes.hpp"

namespace proxgen::emit {

Cholesky cholesky(Emit& e, const Sym& A, const Expr& shift, const std::function<std::string(int, int)>& Lname,
                  const std::function<std::string(int)>& invName) {
  CodeBuilder& cb = e.cb();
  const int n = A.size();
  Cholesky ch{Sym(n), std::vector<Expr>(std::size_t(n))};
  for (int j = 0; j < n; ++j) {
    Expr d = A(j, j) + shift;
    for (int k = 0; k < j; ++k) d -= cb.mul(ch.L(j, k), ch.L(j, k));
    const Expr r = cb.sqrt(d, "r");
    ch.inv[std::size_t(j)] = e.put(invName(j), cb.recip(r, "inv"));
    for (int i = j + 1; i < n; ++i) {
      Expr x = A(i, j);
      for (int k = 0; k < j; ++k) x -= cb.mul(ch.L(i, k), ch.L(j, k));
      ch.L(i, j) = e.put(Lname(i, j), cb.mul(cb.flat(x), ch.inv[std::size_t(j)]));
    }
  }
  return ch;
}

std::vector<Expr> forwardSolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b) {
  const int n = L.size();
  std::vector<Expr> y(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Expr x = b[std::size_t(i)];
    for (int k = 0; k < i; ++k) x -= cb.mul(L(i, k), y[std::size_t(k)]);
    y[std::size_t(i)] = cb.flat(cb.mul(cb.flat(x), inv[std::size_t(i)]), "y");
  }
  return y;
}

std::vector<Expr> backwardSolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& y) {
  const int n = L.size();
  std::vector<Expr> x(static_cast<std::size_t>(n));
  for (int i = n - 1; i >= 0; --i) {
    Expr s = y[std::size_t(i)];
    // x[i + 1] last: it is the one just solved, so the sum runs while it is being solved.
    for (int k = n - 1; k > i; --k) s -= cb.mul(L(k, i), x[std::size_t(k)]);
    x[std::size_t(i)] = cb.flat(cb.mul(cb.flat(s), inv[std::size_t(i)]), "x");
  }
  return x;
}

std::vector<Expr> choleskySolve(CodeBuilder& cb, const Sym& L, const std::vector<Expr>& inv, const std::vector<Expr>& b) {
  return backwardSolve(cb, L, inv, forwardSolve(cb, L, inv, b));
}

}  // namespace proxgen::emit

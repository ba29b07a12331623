// proxLTLs (docs/algorithms.md §5.2): joint-space primal. M_mu = M + mu J^T J keeps the
// branch-induced sparsity of M, so one sparse L^T D L factorisation serves all
// iterations; each iteration is one sparse solve plus the multiplier update.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

void proxLtls(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations);

}  // namespace proxgen

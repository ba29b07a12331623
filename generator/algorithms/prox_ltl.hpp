// proxLTL (docs/algorithms.md §5.1): joint-space dual. M by CRBA, sparse L^T D L
// factorisation (Featherstone 2005), Delassus J M^-1 J^T through the factor,
// Cholesky of G + I/mu, proximal iterations, qdd by one solve.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

void proxLtl(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations);

}  // namespace proxgen

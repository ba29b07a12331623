// proxPV (docs/algorithms.md §4.2): proximal Popov-Vereshchagin. One ABA-like backward
// sweep that also carries, for the constraint rows of each subtree, their force
// directions KA, free accelerations lA and Delassus block LA; at the root the
// m x m Delassus matrix G is factored once with I/mu and the proximal
// iterations run on that factor; one forward sweep gives qdd.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// K proximal iterations from lambda = 0; results in d.qdd, d.lambda (layout order).
void proxPv(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations);
/// The same from lambda = *lambda0 (layout order; the warm start,
/// docs/algorithms.md §4.3; null: 0). K = 0: lambda = lambda0 and the motion under its forces.
void proxPvFrom(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau, double mu, int iterations,
                const VecX* lambda0);

}  // namespace proxgen

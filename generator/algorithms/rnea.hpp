// Recursive Newton-Euler: inverse dynamics tau = M(q) qdd + h(q, v).
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// Returns d.tau = RNEA(q, v, qdd), gravity from the model.
const VecX& rnea(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& qdd);

/// d.h = RNEA(q, v, 0): Coriolis, centrifugal and gravity terms.
const VecX& nonLinearEffects(const System& sys, Data& d, const VecX& q, const VecX& v);

}  // namespace proxgen

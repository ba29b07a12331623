// Composite-rigid-body algorithm: the joint-space inertia matrix M(q).
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// Returns d.M (full, symmetric).
const MatX& crba(const System& sys, Data& d, const VecX& q);

}  // namespace proxgen

// What bench_pinocchio.cpp offers beside the suite's peers (common.hpp,
// PeerEntry) to executables that link it where CMake finds Pinocchio
// (bench/pinocchio.cmake, bench/derivatives.cmake). This header itself needs no
// Pinocchio: bench_derivatives.cpp reads ConstrainedDerivatives either way.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/model.hpp"
#include "model/state.hpp"

namespace proxgen::bench {

/// The constrained solution and its derivatives in proxgen's conventions
/// (algorithms/derivatives.hpp: M qdd + h + J^T lambda = tau, rows in layout
/// order, q tangents along q (+) dq), dense, row = output, column = input.
struct ConstrainedDerivatives {
  VecX qdd, lambda;
  MatX dqdd_dq, dqdd_dv, dqdd_dtau;           // nv x nv
  MatX dlambda_dq, dlambda_dv, dlambda_dtau;  // nc x nv
};

/// pinocchio::constraintDynamics followed by
/// pinocchio::computeConstraintDynamicsDerivatives on one case, with the
/// constraint models the suite's pin_caba / pin_pv use.
class PinocchioConstraintDerivatives {
 public:
  virtual ~PinocchioConstraintDerivatives() = default;
  /// Both calls on state k of the pool given at construction.
  virtual void call(int k) = 0;
  /// The last call's results, converted to proxgen's conventions (lambda's sign).
  virtual void read(ConstrainedDerivatives& out) const = 0;
  /// Pinocchio's settings.iter after the last call (must be K: accuracy 0).
  virtual int iterations() const = 0;
};

/// Settings mu_pinocchio = 1 / mu, max_iter = K, accuracy 0. `states` must outlive the result.
std::unique_ptr<PinocchioConstraintDerivatives> makePinocchioConstraintDerivatives(const std::string& caseName,
                                                                                   const System& sys,
                                                                                   const std::vector<State>& states,
                                                                                   double mu, int K);

/// pinocchio::computeRNEADerivatives(model, data, q, v, a) on one case: Carpentier and
/// Mansard's analytical RNEA derivatives, in the world frame. Its algorithm also
/// fills the upper triangle of M (data.M), which it cannot skip.
class PinocchioRneaDerivatives {
 public:
  virtual ~PinocchioRneaDerivatives() = default;
  /// The call at state k of the pool given at construction, with a = that state's tau
  /// (any vector does: the cost does not depend on it).
  virtual void call(int k) = 0;
  /// dtau/dq and dtau/dv of the last call (same tangent convention as proxgen's).
  virtual void read(MatX& dtau_dq, MatX& dtau_dv) const = 0;
};

/// `states` must outlive the result.
std::unique_ptr<PinocchioRneaDerivatives> makePinocchioRneaDerivatives(const std::string& caseName,
                                                                       const System& sys,
                                                                       const std::vector<State>& states);

}  // namespace proxgen::bench

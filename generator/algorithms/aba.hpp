// Articulated-body algorithm: unconstrained forward dynamics, and the per-body
// steps that constrainedABA and proxPV share with it.
#pragma once

#include "algorithms/data.hpp"

namespace proxgen {

/// Returns d.qdd = M^-1 (tau - h).
const VecX& aba(const System& sys, Data& d, const VecX& q, const VecX& v, const VecX& tau);

namespace aba_steps {
/// Kinematics pass: liMi, oMi, v_i, c_i; IA_i = I_i, pA_i = v_i x* I_i v_i.
void initialise(const System& sys, Data& d, const VecX& q, const VecX& v);
/// Eliminates joint i: U_i, D_i^-1, u_i, then adds the articulated inertia and
/// bias of body i into its parent.
void eliminate(const System& sys, Data& d, int i, const VecX& tau);
/// a'_i = X_i a_p + c_i ; qdd_i = D_i^-1 (u_i - U_i^T a'_i) ; a_i = a'_i + S_i qdd_i.
void accelerate(const System& sys, Data& d, int i);
/// a_0 = -a_g, the gravity trick (docs/algorithms.md §1).
void setRootAcceleration(const System& sys, Data& d);
}  // namespace aba_steps

}  // namespace proxgen

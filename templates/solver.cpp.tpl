R"proxgen({banner}
#include "{name}.hpp"

#include "proxgen/runtime.hpp"

namespace {name} {{
namespace {{

// The parts the functions below call in order: each holds a few bodies' blocks.
{parts}// Joint transforms, body velocities v, velocity-product accelerations c, bias
// forces pA = v x* I v, gravity in the support bodies, constraint right-hand sides k.
void kinematics(const Scalar* q, const Scalar* v, Workspace& w) noexcept {{
{kinematics}}}

{free_bodies}{constraint_joints}}}  // namespace

// constrainedABA: the penalty mu K^T K at the constrained bodies, one full
// sweep, then iterations 2..K as reduced sweeps over the support.
void constrained_aba(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,
                     Scalar* qdd, Scalar* lambda) noexcept {{
{caba}}}

// proxPV: one sweep carrying the constraint rows up the support, the Delassus
// matrix G + I/mu factored once at the root, K proximal solves, one forward sweep.
void prox_pv(const Scalar* q, const Scalar* v, const Scalar* tau, const Settings& s, Workspace& w,
             Scalar* qdd, Scalar* lambda) noexcept {{
{pv}}}
{constraint_functions}
}}  // namespace {name}
)proxgen"

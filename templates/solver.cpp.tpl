R"proxgen({banner}
#include "{name}.hpp"

#include "proxgen/lanes.hpp"  // the runtime, and the lanes of sincos_run

namespace {name} {{

// This file was printed for the runtime of the same version (runtime.hpp).
static_assert(proxgen_rt::version_major == version_major);
static_assert(proxgen_rt::version_minor == version_minor);

namespace {{

// nc multipliers: an array of two picks by a schedule flag, {{zeros, given}}
// (docs/algorithms.md section 4.4).
using MultiplierRows = const Scalar*;

// The parts the functions below call in order: each holds a few bodies' blocks.
{part_helpers}{parts}{helpers}{free_bodies}}}  // namespace

{definitions}}}  // namespace {name}
)proxgen"

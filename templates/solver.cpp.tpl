R"proxgen({banner}
#include "{name}.hpp"

#include "proxgen/runtime.hpp"

namespace {name} {{
namespace {{

// The parts the functions below call in order: each holds a few bodies' blocks.
{parts}{helpers}{free_bodies}}}  // namespace

{definitions}}}  // namespace {name}
)proxgen"

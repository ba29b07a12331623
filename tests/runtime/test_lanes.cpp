// proxgen_rt::lanes over the compilers' vector extension (GCC, Clang): lanes_checks.inc.
#include "lanes_checks.inc"

static_assert(PROXGEN_RT_LANES_VECTOR == 1, "GCC and Clang build the vector-extension lanes");

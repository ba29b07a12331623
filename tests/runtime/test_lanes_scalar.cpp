// proxgen_rt::lanes over the plain-array fallback (what a compiler without
// GCC's vector extension builds), forced here: lanes_checks.inc.
#define PROXGEN_RT_LANES_SCALAR 1
#include "lanes_checks.inc"

static_assert(PROXGEN_RT_LANES_VECTOR == 0, "PROXGEN_RT_LANES_SCALAR selects the plain arrays");

// sincos_run and sincos_joint in the mode of the build's own flags (at the
// x86-64 baseline: the run in two lanes before joints that call sincos, each
// joint its own where they inline it): sincos_run_checks.inc.
#include "sincos_run_checks.inc"
#if defined(__x86_64__) && !defined(__AVX__) && !defined(PROXGEN_RT_LANES_SCALAR)
static_assert(PROXGEN_RT_SINCOS_RUN_WIDTH == 1 && PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH == 2,
              "x86-64 baseline: the run in two lanes for the called form only");
#endif

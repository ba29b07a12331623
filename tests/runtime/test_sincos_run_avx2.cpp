// sincos_run in 4 lanes: this file is compiled with -mavx2 -ffp-contract=off
// (tests/CMakeLists.txt, x86-64 only) and its tests skip on a processor
// without AVX2; sincos_run_checks.inc.
#if defined(__AVX2__)
#define PROXGEN_TEST_SINCOS_ISA "avx2"
#endif
#include "sincos_run_checks.inc"
#if defined(__AVX2__)
static_assert(PROXGEN_RT_SINCOS_RUN == 1 && PROXGEN_RT_SINCOS_RUN_WIDTH == 4 &&
                  PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH == 4, "AVX2: the run in 4 lanes");
#endif

// sincos_run in 8 lanes: this file is compiled with -mavx512f -ffp-contract=off
// (tests/CMakeLists.txt, x86-64 only) and its tests skip on a processor
// without AVX-512F; sincos_run_checks.inc.
#if defined(__AVX512F__)
#define PROXGEN_TEST_SINCOS_ISA "avx512f"
#endif
#include "sincos_run_checks.inc"
#if defined(__AVX512F__)
static_assert(PROXGEN_RT_SINCOS_RUN == 1 && PROXGEN_RT_SINCOS_RUN_WIDTH == 8 &&
                  PROXGEN_RT_SINCOS_RUN_CALLED_WIDTH == 8, "AVX-512: the run in 8 lanes");
#endif

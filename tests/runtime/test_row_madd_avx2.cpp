// row_madd and row_product in 4 doubles a vector: this file is compiled with
// -mavx2 -ffp-contract=off (tests/CMakeLists.txt, x86-64 only) and its tests skip
// on a processor without AVX2; row_madd_checks.inc.
#if defined(__AVX2__)
#define PROXGEN_TEST_ROW_ISA "avx2"
#endif
#include "row_madd_checks.inc"
#if defined(__AVX2__)
static_assert(PROXGEN_RT_ROW_BYTES == 32, "AVX2: rows in 32-byte vectors");
#endif

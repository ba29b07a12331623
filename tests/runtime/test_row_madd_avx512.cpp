// row_madd and row_product in 8 doubles a vector: this file is compiled with
// -mavx512f -ffp-contract=off (tests/CMakeLists.txt, x86-64 only) and its tests
// skip on a processor without AVX-512F; row_madd_checks.inc.
#if defined(__AVX512F__)
#define PROXGEN_TEST_ROW_ISA "avx512f"
#endif
#include "row_madd_checks.inc"
#if defined(__AVX512F__)
static_assert(PROXGEN_RT_ROW_BYTES == 64, "AVX-512: rows in 64-byte vectors");
#endif

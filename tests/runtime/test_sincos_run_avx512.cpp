// sincos_run in 8 lanes: this file is compiled with -mavx512f -ffp-contract=off
// (tests/CMakeLists.txt, x86-64 only) and its tests skip on a processor
// without AVX-512F; sincos_run_checks.inc.
#include "sincos_run_checks.inc"
#if defined(__AVX512F__)
static_assert(PROXGEN_RT_SINCOS_RUN == 1 && PROXGEN_RT_SINCOS_RUN_WIDTH == 8, "AVX-512: the run in 8 lanes");
#endif

class SkipWithoutAvx512 : public ::testing::Environment {
 public:
  void SetUp() override {
#if defined(__AVX512F__)
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx512f")) GTEST_SKIP() << "this processor has no AVX-512F";
#else
    GTEST_SKIP() << "not compiled for AVX-512 (not an x86-64 build)";
#endif
  }
};
const auto* const kSkip = ::testing::AddGlobalTestEnvironment(new SkipWithoutAvx512);

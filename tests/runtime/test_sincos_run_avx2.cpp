// sincos_run in 4 lanes: this file is compiled with -mavx2 -ffp-contract=off
// (tests/CMakeLists.txt, x86-64 only) and its tests skip on a processor
// without AVX2; sincos_run_checks.inc.
#include "sincos_run_checks.inc"
#if defined(__AVX2__)
static_assert(PROXGEN_RT_SINCOS_RUN == 1 && PROXGEN_RT_SINCOS_RUN_WIDTH == 4, "AVX2: the run in 4 lanes");
#endif

class SkipWithoutAvx2 : public ::testing::Environment {
 public:
  void SetUp() override {
#if defined(__AVX2__)
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this processor has no AVX2";
#else
    GTEST_SKIP() << "not compiled for AVX2 (not an x86-64 build)";
#endif
  }
};
const auto* const kSkip = ::testing::AddGlobalTestEnvironment(new SkipWithoutAvx2);

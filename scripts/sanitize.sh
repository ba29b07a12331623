#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the project and its
# test suite (clang), in build-asan, then ctest there. The same build holds the
# libFuzzer targets (tests/fuzz/run.sh runs them from it): everything is
# compiled once, the code the fuzzers drive with their coverage instrumentation.
#
# What runs: every GoogleTest suite (tests/*/test_*.cpp) and the generated-solver
# tests, compiled with -fsanitize=address,undefined and with assertions on (no
# NDEBUG: Eigen's index checks and _GLIBCXX_ASSERTIONS catch what ASan cannot
# see inside fixed-size storage). Any sanitizer report aborts the test.
# Why clang, the tests at -O0 and the library at -O1: on this 2-core machine
# clang -O0 compiles the Eigen-heavy sources 3x faster than gcc -O1 -g
# (dense_reference.cpp: 18 s against 56 s), and the library, where the tests
# spend their time, runs 5 to 10 times faster at -O1 (below), which is what
# keeps this stage inside CI's time budget.
# What does not run:
#   - label `package` (downstream_project): it installs proxgen and configures
#     another project with the installed package; that tests packaging, not
#     memory safety, and the Release ctest run covers it.
#   - the benchmarks (PROXGEN_BUILD_BENCH=OFF, so no `bench-smoke` tests):
#     timing an instrumented build means nothing.
#   - the generated solvers that repeat another's constructs (PROXGEN_TEST_SOLVERS
#     below keeps one per construct): every shared case but iiwa_h3 (Talos and
#     Atlas are the smaller cases' constructs, only more of them; iiwa_h6 and
#     Solo are the arm's weld and the quadruped's contacts on a floating base),
#     the default layouts of the arm and the humanoid and the float quadruped
#     (their _gains, _gains_cons and _cons_float solvers print the same
#     constructs and more functions), the second and third hostile-name solvers
#     (the same constructs under other names), two of the five single-body layouts (the offset
#     and the rows on the hull are each kept once), the float planar arm, and
#     two of the five batched solvers (W = 2 and the iiwa's W = 4: the lanes of
#     the arm's W = 4 and the quadruped's W = 8). The Release run tests them all.
#   - the 32 subset solvers of the run-time schedule's test
#     (PROXGEN_TEST_SCHEDULE_SUBSETS, tests/generated/schedule_subsets.cpp):
#     each is the example quadruped's code with fewer feet, a subset of the
#     constructs the quadruped's own solver (built here) already runs, and the
#     schedule's flags run in every harness built here; the Release run
#     compares them. Under ASan they were about 4.5 minutes of the build.
#   - ReservedNames.* (tests/cli/test_reserved_names.cpp): they run the host g++
#     over generated code to list and collide with library names; what they
#     test is the C++ namespace, not memory, and instrumenting proxgen adds
#     nothing to it (about 75 s of CPU under ASan); the Release run has them.
#   - the embedded stage's solvers and vectors (PROXGEN_EMBEDDED_INPUTS_TARGET):
#     they are for the cross-compiled firmware, which this build does not make.
#
# Environment: ASAN_BUILD (default build-asan), JOBS (default nproc),
# CTEST_ARGS (extra ctest arguments, e.g. "-R hardening").
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${ASAN_BUILD:-$root/build-asan}"
jobs="${JOBS:-$(nproc)}"

# Every check aborts on its first report, except `null`, which is recoverable so
# that the one Eigen false alarm below can be suppressed (halt_on_error=1 still
# aborts on any other null report).
# The code that reads the user's files (proxgen_core, the cases reader, the CLI
# and the fuzz targets: PROXGEN_GENERATOR_EXTRA_FLAGS) gets three things more:
#   - libFuzzer's coverage instrumentation, which only the fuzzer reads;
#   - UBSan's pointer-overflow check (an address that wraps around);
#   - -O1, ASan's recommended level: nearly every test's time is spent in this
#     library (generation, parsing, the generic algorithms). Measured on the
#     slowest tests, -O0 -> -O1: NoAllocation.DerivativesOnEverySharedCase
#     48 -> 4 s, Derivatives.ConstrainedDynamicsMatchDifferencesOfConvergedSolves
#     57 -> 11 s, Bounds.StateNestingValuesAndKeysAreBoundedWhileParsing 36 ->
#     8 s; its files compile 1.4 to 1.8 times slower.
# On the test suites and the generated solvers the first two cost without telling
# anything: the generated code indexes fixed arrays by constants, which `bounds`
# checks, and the tests' own code is not what is under test. Measured on one
# core: the largest generated solver (humanoid_gains_cons.cpp) 50 s with both,
# 27 s without; an Eigen-heavy test (test_analytic.cpp) 22.4 s and 13.8 s.
flags="-fsanitize=address,undefined -fno-sanitize=pointer-overflow -fno-sanitize-recover=all -fsanitize-recover=null -fno-omit-frame-pointer -D_GLIBCXX_ASSERTIONS"
generator_flags="-O1 -fsanitize=pointer-overflow,fuzzer-no-link"
solvers="arm_float;arm_gains;arm_gains_cons;arm_mass_matrix_only;quadruped;quadruped_cons_float;humanoid_gains_cons"
solvers+=";humanoid_hands;hostile_names;iiwa_h3;single_body_hull_6d_offset;single_body_hull_3d;single_body_hull_limbs"
solvers+=";arm_planar;planar_mobile;floating_joint;arm_batch4;arm_float_batch8;quadruped_batch8"
# lld: a sanitizer test executable links in 2.2 s with it, 9.1 s with GNU ld
# (the instrumented library is 400 MB).
ld=""
command -v ld.lld >/dev/null && ld=" -fuse-ld=lld"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O0 -gline-tables-only" -DPROXGEN_BUILD_BENCH=OFF -DPROXGEN_FUZZ=ON -DPROXGEN_EMBEDDED_INPUTS_TARGET=OFF \
  "-DPROXGEN_TEST_SOLVERS=$solvers" -DPROXGEN_TEST_SCHEDULE_SUBSETS=OFF "-DCMAKE_CXX_FLAGS=$flags" \
  "-DPROXGEN_GENERATOR_EXTRA_FLAGS=$generator_flags" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined$ld" \
  "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined$ld" > "$build-configure.log" 2>&1 \
  || { cat "$build-configure.log"; exit 1; }
cmake --build "$build" -j "$jobs"

# detect_leaks: every test process must free what it allocates.
# detect_stack_use_after_return: catches references to a finished solve's locals.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:detect_stack_use_after_return=1:abort_on_error=1:strict_string_checks=1}"
# Eigen 3.4's triangular solve takes &rhs.coeffRef(0, 0) of a right-hand side
# with zero columns (an LLT solve with J^T when there are no constraint rows):
# a reference bound to an empty matrix's null data pointer, never read.
cat > "$build/ubsan.supp" <<'SUPP'
null:Eigen/src/Core/PlainObjectBase.h
SUPP
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1:suppressions=$build/ubsan.supp}"
# glibc's setlocale keeps the locale path it builds from LOCPATH (argz) for the
# life of the process: tests/cli/test_determinism.cpp sets a comma locale that way.
cat > "$build/lsan.supp" <<'SUPP'
leak:argz_add_sep
SUPP
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$build/lsan.supp}"
# The generated-solver tests compare 5 random states instead of 100: at -O0
# under ASan each state costs seconds of Eigen decompositions, and 5 already run
# every line of every solver (the Release run does the 100).
export PROXGEN_HARNESS_STATES="${PROXGEN_HARNESS_STATES:-5}"
# shellcheck disable=SC2086
ctest --test-dir "$build" --output-on-failure -j "$jobs" -LE package -E '^ReservedNames\.' ${CTEST_ARGS:-}
echo "sanitize: ASan + UBSan test run passed"

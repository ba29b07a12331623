#!/usr/bin/env bash
# Every test: the build with all test suites (unit, generated-vs-generic,
# downstream package, benchmark smoke runs), then the embedded checks under
# qemu, the sanitizer build and the bounded fuzz runs.
# Environment: PROXGEN_EMBEDDED=0 leaves out the cross-compiled solvers under
# qemu (tests/embedded/check.sh, about a minute), PROXGEN_HARDENING=0 the ASan +
# UBSan build of the test suite and the bounded fuzz runs.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
# ccache hits across checkouts in different folders (CI clones afresh).
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
start=$(date +%s)
stage() { echo; echo "== [$(( $(date +%s) - start ))s] $*"; }

# lld links the test executables several times faster than GNU ld (docs/benchmarks.md,
# "CI time"); scripts/install-deps.sh installs it, elsewhere GNU ld does the job.
linker=()
if command -v ld.lld >/dev/null; then
  linker=(-DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld
          -DCMAKE_MODULE_LINKER_FLAGS=-fuse-ld=lld)
fi

stage "configure + build (Release)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${linker[@]}"
cmake --build build -j "$jobs"

stage "ctest"
ctest --test-dir build --output-on-failure -j "$jobs"

# The cross toolchain and qemu come from scripts/install-deps.sh; CI always has
# them (a missing tool fails there), elsewhere the stage says what it needs.
if [ "${PROXGEN_EMBEDDED:-1}" = 1 ]; then
  if command -v arm-none-eabi-g++ >/dev/null && command -v qemu-system-arm >/dev/null || [ "${CI:-}" = true ]; then
    stage "embedded: cross-compile and run under qemu"
    tests/embedded/check.sh build/embedded
  else
    stage "embedded: SKIPPED (needs gcc-arm-none-eabi, libnewlib-arm-none-eabi, libstdc++-arm-none-eabi-newlib, qemu-system-arm: scripts/install-deps.sh)"
  fi
fi

# Hardening: one clang build with ASan + UBSan (and libFuzzer's coverage
# instrumentation) runs the test suite, then each fuzz target from the same
# build for FUZZ_SECONDS (default here 30: five targets, two at a time on two
# cores, each first replaying its
# seed corpus, whose findings are the regressions that matter; CI's 35-minute
# budget has no room for more; tests/fuzz/run.sh alone defaults to 60).
if [ "${PROXGEN_HARDENING:-1}" = 1 ]; then
  if command -v clang++ >/dev/null || [ "${CI:-}" = true ]; then
    stage "ASan + UBSan build of the test suite"
    ASAN_BUILD="$PWD/build-asan" scripts/sanitize.sh
    stage "fuzzing (bounded, ${FUZZ_SECONDS:-30} s per target)"
    FUZZ_SECONDS="${FUZZ_SECONDS:-30}" FUZZ_BUILD="$PWD/build-asan" tests/fuzz/run.sh
  else
    stage "sanitizers and fuzzing: SKIPPED (needs clang and libclang-rt-14-dev: scripts/install-deps.sh)"
  fi
fi
stage "all tests passed"

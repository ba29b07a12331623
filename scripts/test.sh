#!/usr/bin/env bash
# Every test: the build with all test suites (unit, generated-vs-generic,
# downstream package, benchmark smoke runs), then the embedded checks under
# qemu, the sanitizer build and the bounded fuzz runs.
# Environment: PROXGEN_EMBEDDED=1 adds the cross-compiled solvers under qemu
# (tests/embedded/check.sh; not yet part of CI), PROXGEN_HARDENING=1 adds the ASan+UBSan build of the test suite
# and the bounded fuzz runs (about 15 more minutes on 2 cores; not yet part of CI).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
# ccache hits across checkouts in different folders (CI clones afresh).
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
start=$(date +%s)
stage() { echo; echo "== [$(( $(date +%s) - start ))s] $*"; }

stage "configure + build (Release)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$jobs"

stage "ctest"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${PROXGEN_EMBEDDED:-0}" = 1 ] && [ -x tests/embedded/check.sh ]; then
  stage "embedded: cross-compile and run under qemu"
  tests/embedded/check.sh build/embedded
fi

if [ "${PROXGEN_HARDENING:-0}" = 1 ]; then
  if [ -x scripts/sanitize.sh ]; then
    stage "ASan + UBSan build of the test suite"
    scripts/sanitize.sh
  fi
  if [ -x tests/fuzz/run.sh ]; then
    stage "fuzzing (bounded)"
    tests/fuzz/run.sh
  fi
fi
stage "all tests passed"

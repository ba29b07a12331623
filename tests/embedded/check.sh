#!/usr/bin/env bash
# Builds and tests the embedded bring-up for both targets, and the formatter on the host, and
# runs the generated solvers under qemu (M7: double, M4F: float) against the host's answers.
#   tests/embedded/check.sh [BUILD_ROOT]       (default BUILD_ROOT: <repo>/build/embedded)
# The solver firmware needs BUILD_ROOT/inputs, written by the host build whose folder holds
# BUILD_ROOT (target proxgen_embedded_inputs: `cmake --build build` makes build/embedded/inputs).
# Environment: PROXGEN_EMBEDDED_INPUTS (another inputs folder), PROXGEN_EMBEDDED_ALL=ON (every
# case, not only the CI set), PROXGEN_EMBEDDED_JOBS (parallel build and test jobs; default nproc).
# Needs: gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib
#        qemu-system-arm cmake (ninja-build optional), python3 and a host g++ (optional).
# Exit status 0 when everything passed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
root=${1:-$repo/build/embedded}

for tool in arm-none-eabi-g++ qemu-system-arm cmake; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "check.sh: $tool not found; apt-get install -y gcc-arm-none-eabi libnewlib-arm-none-eabi" \
         "libstdc++-arm-none-eabi-newlib qemu-system-arm cmake ninja-build" >&2
    exit 2
  fi
done
inputs=${PROXGEN_EMBEDDED_INPUTS:-$root/inputs}
all=${PROXGEN_EMBEDDED_ALL:-OFF}
jobs=${PROXGEN_EMBEDDED_JOBS:-$(nproc)}
if [[ ! -d $inputs ]]; then
  if [[ ${CI:-} == true ]]; then
    echo "check.sh: no solver inputs in $inputs: build the host first (cmake --build build)" >&2
    exit 2
  fi
  echo "check.sh: no solver inputs in $inputs (build the host target proxgen_embedded_inputs):" \
       "bring-up tests only"
  inputs=""
fi
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi

if command -v g++ >/dev/null 2>&1; then
  mkdir -p "$root/host"
  g++ -std=c++17 -O2 -I"$here/support/include" "$here/host/format_test.cpp" \
      "$here/support/src/format.cpp" -o "$root/host/format_test"
  echo "== host: printf-free formatter vs glibc printf"
  "$root/host/format_test"
fi

for cpu in cortex-m7 cortex-m4f; do
  echo "== $cpu"
  cmake "${generator[@]}" -S "$here" -B "$root/$cpu" \
        -DCMAKE_TOOLCHAIN_FILE="$repo/cmake/toolchains/arm-none-eabi-$cpu.cmake" \
        -DPROXGEN_EMBEDDED_INPUTS="$inputs" -DPROXGEN_EMBEDDED_ALL="$all"
  cmake --build "$root/$cpu" -j "$jobs"
  ctest --test-dir "$root/$cpu" --output-on-failure -j "$jobs"
done

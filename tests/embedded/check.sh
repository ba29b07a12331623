#!/usr/bin/env bash
# Builds and tests the embedded bring-up for both targets, and the formatter on the host.
#   tests/embedded/check.sh [BUILD_ROOT]       (default BUILD_ROOT: <repo>/build/embedded)
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
        -DCMAKE_TOOLCHAIN_FILE="$repo/cmake/toolchains/arm-none-eabi-$cpu.cmake"
  cmake --build "$root/$cpu"
  ctest --test-dir "$root/$cpu" --output-on-failure
done

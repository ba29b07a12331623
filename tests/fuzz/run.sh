#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in their own build
# folder and runs each for a bounded time from the checked-in seed corpus.
# Fails if any target finds a crash, a leak, a timeout (>10 s per input), an
# out-of-memory (>2 GB) or a broken promise (see fuzz_common.hpp).
#
# Environment:
#   FUZZ_SECONDS   time per target (default 60)
#   FUZZ_TARGETS   targets to run (default: every fuzz_* target built)
#   FUZZ_BUILD     build folder (default build-fuzz)
#   JOBS           build parallelism (default nproc)
# New corpus entries go to $FUZZ_BUILD/corpus/<target> (not into the repository);
# a finding is written to $FUZZ_BUILD/artifacts/ and the script exits 1.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${FUZZ_BUILD:-$root/build-fuzz}"
seconds="${FUZZ_SECONDS:-60}"
jobs="${JOBS:-$(nproc)}"

flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
mkdir -p "$build"
# A build folder configured with PROXGEN_FUZZ=ON already (scripts/sanitize.sh's,
# which CI passes here) is used as it is; otherwise configure one for fuzzing.
if ! grep -qs '^PROXGEN_FUZZ:BOOL=ON' "$build/CMakeCache.txt"; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DPROXGEN_FUZZ=ON -DPROXGEN_BUILD_TESTS=OFF -DPROXGEN_BUILD_BENCH=OFF \
    "-DCMAKE_CXX_FLAGS=$flags" > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
fi
cmake --build "$build" --target fuzz_all -j "$jobs"

if [ -z "${FUZZ_TARGETS:-}" ]; then
  FUZZ_TARGETS=""
  for f in "$build"/tests/fuzz/fuzz_*; do
    [ -f "$f" ] && [ -x "$f" ] && FUZZ_TARGETS+="${f##*/fuzz_} "
  done
fi
targets="$FUZZ_TARGETS"
mkdir -p "$build/artifacts"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
failed=()
summary=()
for t in $targets; do
  corpus="$build/corpus/$t"
  mkdir -p "$corpus"
  cp -n "$here/corpus/$t"/* "$corpus"/ 2>/dev/null || true
  dict=()
  [ -f "$here/$t.dict" ] && dict=("-dict=$here/$t.dict")
  log="$build/fuzz_$t.log"
  echo "== fuzz_$t: ${seconds}s from $(ls "$corpus" | wc -l) inputs"
  if "$build/tests/fuzz/fuzz_$t" "${dict[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
       -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" "$corpus" > "$log" 2>&1; then
    runs=$(grep -a -o 'Done [0-9]* runs' "$log" | tail -1)
    summary+=("fuzz_$t: ok, ${runs#Done }")
  else
    failed+=("$t")
    summary+=("fuzz_$t: FAILED (log: $log)")
    grep -a -B2 -A25 -E 'ERROR|broken promise|runtime error' "$log" | head -60 || tail -40 "$log"
  fi
done
echo
printf '%s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in: ${failed[*]}; inputs in $build/artifacts/ (reproduce: $build/tests/fuzz/fuzz_<target> <input>)"
  exit 1
fi
echo "fuzz: no findings"

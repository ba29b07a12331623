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
#   JOBS           build parallelism and targets run at once (default nproc)
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
# The targets run side by side, `jobs` at a time (each is one process on one
# core): the same fuzzing time per target in half the wall time on two cores.
run_target() {
  local t="$1" corpus="$build/corpus/$1" log="$build/fuzz_$1.log" dict=()
  mkdir -p "$corpus"
  cp -n "$here/corpus/$t"/* "$corpus"/ 2>/dev/null || true
  [ -f "$here/$t.dict" ] && dict=("-dict=$here/$t.dict")
  echo "== fuzz_$t: ${seconds}s from $(ls "$corpus" | wc -l) inputs"
  local rc=0
  "$build/tests/fuzz/fuzz_$t" "${dict[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" "$corpus" > "$log" 2>&1 || rc=$?
  echo "$rc" > "$build/fuzz_$t.rc"
}
for t in $targets; do
  rm -f "$build/fuzz_$t.rc"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
  run_target "$t" &
done
wait
failed=()
summary=()
for t in $targets; do
  log="$build/fuzz_$t.log"
  if [ "$(cat "$build/fuzz_$t.rc" 2>/dev/null)" = 0 ]; then
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

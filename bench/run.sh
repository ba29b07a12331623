#!/bin/sh
# bench/run.sh [BUILD_DIR]: build the benchmarks in Release, run the suite, the
# callgrind instruction counts, the scaling study and the Python module's
# overhead (bench/python_overhead.py, when the build has the Python package),
# and write bench/RESULTS.md with its plots (docs/benchmarks.md). BUILD_DIR
# defaults to build-bench in the source tree.
#
# Environment knobs (defaults in brackets):
#   JOBS [1]          ninja -j for the build
#   REPETITIONS [20]  repetitions per benchmark (the report takes their median)
#   MIN_TIME [0.1]    seconds per repetition (--benchmark_min_time)
#   CALLS [1000]      calls per callgrind run (the other run makes none)
#   MARCH [native]    -march of the whole build (PROXGEN_MARCH); MARCH= for the
#                     compiler's default (x86-64 baseline)
#   CMAKE_ARGS []     extra configure arguments, e.g. -DPROXGEN_BENCH_GENERATED=OFF
#   SKIP_CALLGRIND, SKIP_SCALING, SKIP_COMPILE, SKIP_PYTHON, SKIP_LIBRARY: set to 1 to leave that part out
# The dynamics library's section (bench_joint_space.cpp on every case,
# count_calls.py --library, delassus_scaling.py, library_report.py) comes after
# report.py, which rewrites RESULTS.md without it. valgrind 3.19 cannot decode
# AVX-512: on such a machine run with MARCH= for the instruction counts.
set -eu

here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
build=${1:-$root/build-bench}
case $build in /*) ;; *) build=$(pwd)/$build ;; esac
results=$build/bench/results
reps=${REPETITIONS:-20}
min_time=${MIN_TIME:-0.1}
march=${MARCH-native}

echo "== configure and build ($build, Release)"
# shellcheck disable=SC2086  # CMAKE_ARGS is a list of arguments
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPROXGEN_BENCH_REUSE_TEST_SOLVERS=OFF \
  -DPROXGEN_MARCH="$march" -DPROXGEN_BENCH_LIBRARY_CASES=ALL ${CMAKE_ARGS:-} >/dev/null
# The Python part needs the package's build (PROXGEN_BUILD_PYTHON) and the test
# module of the example quadruped (tests/python, PROXGEN_BUILD_TESTS).
python_targets=""
if [ "${SKIP_PYTHON:-0}" != 1 ]; then
  if ninja -C "$build" -t targets all | grep -q '^pymod_quadruped:'; then
    python_targets="proxgen_python_package pymod_quadruped"
  else
    echo "run.sh: no Python module in this build (PROXGEN_BUILD_PYTHON or PROXGEN_BUILD_TESTS off), no Python section" >&2
  fi
fi
# shellcheck disable=SC2086  # python_targets is a list of targets
ninja -C "$build" -j"${JOBS:-1}" proxgen_bench_all $python_targets
mkdir -p "$results"

gbench_flags="--benchmark_repetitions=$reps --benchmark_min_time=$min_time
  --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
  --benchmark_out_format=json"

echo "== suite: $reps repetitions of ${min_time}s, random interleaving"
# shellcheck disable=SC2086
"$build/bench/proxgen_bench" $gbench_flags --benchmark_out="$results/suite.json"

scaling_json=""
if [ "${SKIP_SCALING:-0}" != 1 ]; then
  echo "== scaling study on synthetic robots"
  # shellcheck disable=SC2086
  "$build/bench/proxgen_bench_scaling" --out "$results/scaling-models" $gbench_flags \
    --benchmark_out="$results/scaling.json"
  scaling_json=$results/scaling.json
fi

python_json=""
if [ -n "$python_targets" ]; then
  # The interpreter the package was built for (Debian's /usr/bin/python3 by default: docs/python.md).
  python_exe=$(sed -n 's/^Python3_EXECUTABLE:FILEPATH=//p' "$build/CMakeCache.txt")
  echo "== Python module against the C++ call ($python_exe)"
  PYTHONPATH="$build/python:$build/tests/python/modules/quadruped" PYTHONDONTWRITEBYTECODE=1 \
    "${python_exe:-/usr/bin/python3}" "$here/python_overhead.py" --out "$results/python.json" >/dev/null
  python_json=$results/python.json
fi

# Callgrind last: its counts do not depend on the machine's load, the timings above do.
calls_json=""
if [ "${SKIP_CALLGRIND:-0}" != 1 ]; then
  if command -v valgrind >/dev/null; then
    echo "== instructions per call (callgrind, ${CALLS:-1000} calls minus none)"
    python3 "$here/count_calls.py" "$build" "$results/calls.json" --calls "${CALLS:-1000}"
    calls_json=$results/calls.json
  else
    echo "run.sh: valgrind not found, no instruction counts" >&2
  fi
fi

echo "== report"
set -- --build "$build" --suite "$results/suite.json" --out-dir "$here" \
  --command "bench/run.sh (REPETITIONS=$reps MIN_TIME=$min_time CALLS=${CALLS:-1000} MARCH=$march)"
[ -n "$calls_json" ] && set -- "$@" --calls "$calls_json"
[ -n "$scaling_json" ] && set -- "$@" --scaling "$scaling_json"
[ -n "$python_json" ] && set -- "$@" --python "$python_json"
[ "${SKIP_COMPILE:-0}" = 1 ] && set -- "$@" --no-compile
python3 "$here/report.py" "$@"

if [ "${SKIP_LIBRARY:-0}" != 1 ]; then
  echo "== the dynamics library against its generic twins"
  load=$(cut -d' ' -f1-3 /proc/loadavg | sed 's/ /, /g')
  # shellcheck disable=SC2086
  "$build/bench/proxgen_bench_joint_space" $gbench_flags --benchmark_out="$results/library.json"
  set -- --build "$build" --timings "$results/library.json" --results "$here/RESULTS.md" --load "$load" \
    --command "bench/run.sh (REPETITIONS=$reps MIN_TIME=$min_time CALLS=${CALLS:-1000} MARCH=$march): proxgen_bench_joint_space, count_calls.py --library, delassus_scaling.py"
  if [ "${SKIP_CALLGRIND:-0}" != 1 ] && command -v valgrind >/dev/null; then
    python3 "$here/count_calls.py" "$build" "$results/library-calls.json" --library --calls "${CALLS:-1000}"
    set -- "$@" --calls "$results/library-calls.json"
  fi
  if [ "${SKIP_SCALING:-0}" != 1 ]; then
    cg=""
    [ "${SKIP_CALLGRIND:-0}" != 1 ] && command -v valgrind >/dev/null && cg=--callgrind
    python3 "$here/delassus_scaling.py" "$build" "$results/delassus-scaling.json" $cg
    set -- "$@" --scaling "$results/delassus-scaling.json"
  fi
  python3 "$here/library_report.py" "$@"
fi

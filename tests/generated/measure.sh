#!/usr/bin/env bash
# Generation time, compile time (-O2, the solver .cpp alone), object size
# (text + data) and, with --instructions, instructions per call (callgrind,
# K = 3, the layout's mu) of the generated solvers of the nine shared cases:
# the table "Generation and compile cost" of docs/benchmarks.md.
#
#   tests/generated/measure.sh BUILD_DIR [--instructions] [--cxx g++] [--march native]
#
# BUILD_DIR holds the built `proxgen` (BUILD_DIR/generator/proxgen); the models
# are ../shared/models (or $PROXGEN_MODELS_DIR). Times are wall-clock seconds
# of one run and user-CPU seconds; on a loaded machine expect them to spread.
# --march X compiles with -march=X (default: the compiler's, x86-64 baseline).
# The options are those of every compile of generated code,
# proxgen_solver_compile_options(... CHECKED) of cmake/ProxgenAddSolver.cmake
# (-O2 and, with GCC, -fno-tree-slp-vectorize among them), as the build wrote
# them to BUILD_DIR/generator/solver_compile_options.txt; --cxx should name the
# build's compiler, for which they were chosen.
set -euo pipefail
build=${1:?usage: measure.sh BUILD_DIR [--instructions] [--cxx CXX] [--march X]}
shift
instructions=0
cxx=${CXX:-g++}
march=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --instructions) instructions=1 ;;
    --cxx) cxx=$2; shift ;;
    --march) march=("-march=$2"); shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
options_file=$build/generator/solver_compile_options.txt
[[ -f $options_file ]] || { echo "$options_file missing: configure BUILD_DIR with CMake first" >&2; exit 2; }
read -r -a options < "$options_file"
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
models=${PROXGEN_MODELS_DIR:-$root/../shared/models}
proxgen=$build/generator/proxgen
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cases=$(sed -n 's/^[ ]*-[ ]*name:[ ]*\([A-Za-z0-9_]*\)[ ]*$/\1/p' "$models/cases.yaml")
seconds() { awk -v s="$1" -v e="$2" 'BEGIN { printf "%.2f", (e - s) / 1e9 }'; }

printf '| case | generate s | compile -O2 s (user) | lines | text+data bytes'
[[ $instructions == 1 ]] && printf ' | cABA Ir | PV Ir'
printf ' |\n|---|---|---|---|---'
[[ $instructions == 1 ]] && printf '|---|---'
printf '|\n'
for c in $cases; do
  out=$work/$c
  t0=$(date +%s%N)
  "$proxgen" generate --cases "$models/cases.yaml" --case "$c" --out "$out" --name "$c" > /dev/null
  t1=$(date +%s%N)
  /usr/bin/time -f '%e %U' -o "$work/time" "$cxx" -std=c++17 "${options[@]}" "${march[@]}" -I"$root/runtime" -I"$out" -c "$out/$c.cpp" -o "$out/$c.o"
  read -r wall user < "$work/time"
  bytes=$(size "$out/$c.o" | awk 'NR == 2 { print $1 + $2 }')
  lines=$(wc -l < "$out/$c.cpp")
  printf '| %s | %s | %s (%s) | %s | %s' "$c" "$(seconds "$t0" "$t1")" "$wall" "$user" "$lines" "$bytes"
  if [[ $instructions == 1 ]]; then
    "$cxx" -std=c++17 -O2 "${march[@]}" -I"$out" -DSOLVER_HEADER="\"$c.hpp\"" -DSOLVER=$c "$here/icount.cpp" "$out/$c.o" -o "$out/icount"
    for alg in 0 1; do
      n1000=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$out/icount" 1000 $alg 2>&1 | sed -n 's/.*Collected : //p')
      n0=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$out/icount" 0 $alg 2>&1 | sed -n 's/.*Collected : //p')
      printf ' | %s' $(( (n1000 - n0) / 1000 ))
    done
  fi
  printf ' |\n'
done

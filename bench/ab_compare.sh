#!/usr/bin/env bash
# A/B comparison of one generated function (docs/benchmarks.md, "Comparing two
# versions of the emitter"): generates CASE with two proxgen executables (or one,
# compiled twice with other flags), links the two sources side by side into
# bench/ab_compare.cpp and prints, for A and B: the object's text bytes, the
# instructions per call (callgrind, (Ir(2N) - Ir(N)) / N, as bench/count_calls.py:
# what the first call does once is not counted as calls), whether the outputs
# agree bit for bit on 1000 random states, and the time of both in one process,
# alternating (21 repetitions, medians and fastest), once with A's object linked
# first and once with B's, and the geometric mean of the two B / A.
#
#   bench/ab_compare.sh PROXGEN_A PROXGEN_B CASE FUNCTION [CALLS]
#
# FUNCTION: constrained_aba, prox_pv, inverse_dynamics, nonlinear_effects,
# mass_matrix, mass_matrix_inverse, inverse_dynamics_derivatives,
# forward_dynamics_derivatives, constrained_dynamics_derivatives. CALLS: calls
# per timed repetition (default 20000). Environment: CXX (default g++), A_FLAGS
# and B_FLAGS (default
# "-O3 -DNDEBUG -fno-tree-slp-vectorize", the bench's flags for generated code,
# at the x86-64 baseline so that callgrind can run it), PROXGEN_MODELS_DIR
# (default ../shared/models beside the repository), AB_DIR (default a new
# temporary folder, kept and printed).
set -euo pipefail
[[ $# -ge 4 ]] || { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
pa=$1 pb=$2 case=$3 fn=$4 calls=${5:-20000}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
models=${PROXGEN_MODELS_DIR:-$root/../shared/models}
cxx=${CXX:-g++}
default_flags="-O3 -DNDEBUG -fno-tree-slp-vectorize"
read -r -a aflags <<< "${A_FLAGS:-$default_flags}"
read -r -a bflags <<< "${B_FLAGS:-$default_flags}"
case $fn in
  constrained_aba | prox_pv) call="$fn(q, v, a, s, w, o[0], o[1])" ;;
  inverse_dynamics) call="inverse_dynamics(q, v, a, lam, w, o[0])" ;;
  nonlinear_effects) call="nonlinear_effects(q, v, w, o[0])" ;;
  mass_matrix | mass_matrix_inverse) call="$fn(q, w, o[0])" ;;
  inverse_dynamics_derivatives) call="inverse_dynamics_derivatives(q, v, a, lam, w, o[0], o[1])" ;;
  forward_dynamics_derivatives) call="forward_dynamics_derivatives(q, v, a, w, o[0], o[1], o[2], o[3])" ;;
  constrained_dynamics_derivatives)
    call="constrained_dynamics_derivatives(q, v, a, s, w, o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7])" ;;
  *) echo "ab_compare.sh: no call for function '$fn'" >&2; exit 2 ;;
esac
dir=${AB_DIR:-$(mktemp -d)}
mkdir -p "$dir"
for side in A B; do
  exe=$pa; [[ $side == B ]] && exe=$pb
  "$exe" generate --cases "$models/cases.yaml" --case "$case" --functions "$fn" --name "$side" --out "$dir" > /dev/null
done
"$cxx" -std=c++17 "${aflags[@]}" -fno-exceptions -fno-rtti -I "$root/runtime" -c "$dir/A.cpp" -o "$dir/A.o" &
"$cxx" -std=c++17 "${bflags[@]}" -fno-exceptions -fno-rtti -I "$root/runtime" -c "$dir/B.cpp" -o "$dir/B.o" &
wait
"$cxx" -std=c++17 -O2 -I "$root/runtime" -I "$dir" "-DCALL=$call" -c "$here/ab_compare.cpp" -o "$dir/main.o"
# Both link orders: one process's B / A can be off by a tenth on the large
# cases (docs/benchmarks.md, "The Delassus columns as loops"), so it is taken
# from two executables, A.o linked first and B.o first.
"$cxx" "$dir/main.o" "$dir/A.o" "$dir/B.o" -o "$dir/ab_compare"
"$cxx" "$dir/main.o" "$dir/B.o" "$dir/A.o" -o "$dir/ab_compare_ba"
ir() {  # instructions of N calls of one side (empty where callgrind cannot run the code)
  local out
  if out=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$dir/ab_compare" count "$1" "$2" 2>&1); then
    sed -n 's/.*Collected : \([0-9]*\).*/\1/p' <<< "$out"
  fi
}
n=20
echo "case $case, function $fn, folder $dir"
for side in A B; do
  bytes=$(size "$dir/$side.o" | awk 'NR == 2 {print $1}')
  i1=$(ir "$side" "$n") i2=$(ir "$side" $((2 * n)))
  if [[ -n $i1 && -n $i2 ]]; then
    echo "$side: text $bytes bytes, $(( (i2 - i1) / n )) instructions per call"
  else  # -march=native with AVX-512: this valgrind does not decode it
    echo "$side: text $bytes bytes, instructions not counted (callgrind cannot run code built with these flags)"
  fi
done
"$dir/ab_compare" check
ab=$("$dir/ab_compare" time "$calls")
ba=$("$dir/ab_compare_ba" time "$calls")
echo "A.o first: $ab"
echo "B.o first: $ba"
ratio() { sed -n 's/.*B \/ A: median \([0-9.]*\), fastest \([0-9.]*\).*/\1 \2/p' <<< "$1"; }
read -r m1 f1 <<< "$(ratio "$ab")"
read -r m2 f2 <<< "$(ratio "$ba")"
awk -v m1="$m1" -v m2="$m2" -v f1="$f1" -v f2="$f2" \
  'BEGIN { printf "B / A over both link orders (geometric mean): median %.3f, fastest %.3f\n", sqrt(m1 * m2), sqrt(f1 * f2) }'

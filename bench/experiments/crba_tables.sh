#!/usr/bin/env bash
# Builds bench/experiments/crba_tables.cpp against one case's generated
# mass_matrix and prints its comparison (docs/benchmarks.md, "CRBA as loops over
# constant tables"). Needs a Release build of proxgen in BUILD (default build/).
#   bench/experiments/crba_tables.sh CASE [BUILD]
set -euo pipefail
case=$1 build=${2:-build}
root=$(cd "$(dirname "$0")/../.." && pwd)
dir=$(mktemp -d)
"$build/generator/proxgen" generate --cases "$root/../shared/models/cases.yaml" --case "$case" --functions mass_matrix --name G --out "$dir" > /dev/null
g++ -std=c++17 -O3 -DNDEBUG -fno-tree-slp-vectorize -fno-exceptions -fno-rtti -I "$root/runtime" -c "$dir/G.cpp" -o "$dir/G.o"
g++ -std=c++17 -O3 -DNDEBUG -fno-tree-slp-vectorize -I "$root/runtime" -I "$root/generator" -I "$dir" -I /usr/include/eigen3 \
  "$root/bench/experiments/crba_tables.cpp" "$dir/G.o" "$build/generator/libproxgen_cases.a" "$build/generator/libproxgen_core.a" \
  -lfmt -lyaml-cpp -lurdfdom_model -ltinyxml2 -lconsole_bridge -o "$dir/crba_tables"
for form in t w s; do "$dir/crba_tables" "$case" T $form; done
for form in g t w s; do
  a=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$dir/crba_tables" "$case" c $form 0 2>&1 | sed -n 's/.*Collected : \([0-9]*\).*/\1/p')
  b=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null "$dir/crba_tables" "$case" c $form 200 2>&1 | sed -n 's/.*Collected : \([0-9]*\).*/\1/p')
  echo "form $form: $(( (b - a) / 200 )) instructions per call"
done

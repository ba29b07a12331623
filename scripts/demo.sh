#!/usr/bin/env bash
# The main job: set up, build proxgen, generate a solver for the example
# quadruped, build and run it, and compare it with the generic solvers.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target proxgen
robot=generated/quadruped
echo "== proxgen check"
build/generator/proxgen check $robot/quadruped.urdf --layout $robot/layout.yaml
echo "== proxgen generate -> build/demo"
build/generator/proxgen generate $robot/quadruped.urdf --layout $robot/layout.yaml --out build/demo --name quadruped
ls -l build/demo
echo "== proxgen verify (generate, compile, run on random states, compare with the generic solvers)"
build/generator/proxgen verify $robot/quadruped.urdf --layout $robot/layout.yaml --samples 50

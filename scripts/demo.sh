#!/usr/bin/env bash
# The main job: installs dependencies, builds, simulates a handful of MOVi-A scenes that no model
# was trained on (seed 3: the test split's seed) with native Bullet and with the shipped FIGNet
# model side by side, prints the speed-accuracy table and the path of the HTML report.
#
#   scripts/demo.sh [--model FILE] [--scenes N]
set -euo pipefail
cd "$(dirname "$0")/.."

model=models/movi-a-small.h5
scenes=4
while [ $# -gt 0 ]; do
  case "$1" in
    --model) model="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    -h|--help) sed -n '2,6p' "$0"; exit 0 ;;
    *) echo "demo: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -f "$model" ] || { echo "demo: no model file '$model'" >&2; exit 1; }

scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target fignet  # the tool only: tests and benchmarks are not needed here
mkdir -p out/demo
fignet=build/release/tools/fignet
"$fignet" generate --preset movi-a --count "$scenes" --seed 3 --out out/demo/scenes.h5
"$fignet" compare --model "$model" --data out/demo/scenes.h5 --report out/demo/report.html

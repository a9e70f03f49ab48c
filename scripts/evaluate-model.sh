#!/usr/bin/env bash
# The measurements docs/training-study.md takes of every model it compares, in one go:
#   scripts/evaluate-model.sh MODEL.h5 [MODEL.h5 ...]
# For each model, into MODEL.eval/ beside it: the test split's rollouts with 1 and 2 turns
# (fignet eval), the canonical stress scenes and a cube at rest for 500 steps with the network
# alone (fignet stress), and scripts/rest_drift.py on the eval-192 split: resting bodies over 100
# and (2 turns) 500 steps, the friction and bias of a push, and the fall of bodies let go in the
# air. Needs the README's release build, data/movi-a/{test,eval-192}.h5 (docs/training-study.md
# says how to generate them) and numpy. Environment: FIGNET (default build/release/tools/fignet),
# THREADS (default 1).
set -euo pipefail
fignet="${FIGNET:-build/release/tools/fignet}" threads="${THREADS:-1}"
[[ $# -ge 1 ]] || { echo "usage: $0 MODEL.h5 [MODEL.h5 ...]" >&2; exit 2; }
for data in data/movi-a/test.h5 data/movi-a/eval-192.h5; do
  [[ -f "$data" ]] || { echo "$0: $data is missing (docs/training-study.md generates it)" >&2; exit 2; }
done
export PYTHONPATH="build/release/python${PYTHONPATH:+:$PYTHONPATH}" OMP_NUM_THREADS="$threads"
python="${PYTHON:-python3}"
for model in "$@"; do
  [[ -f "$model" ]] || { echo "$0: no model file '$model'" >&2; exit 2; }
  out="${model%.h5}.eval"
  mkdir -p "$out"
  echo "== $model → $out/"
  for turns in 1 2; do
    "$fignet" eval --model "$model" --data data/movi-a/test.h5 --threads "$threads" \
      --turns "$turns" --no-baseline >"$out/test-turns$turns.txt" 2>&1
    "$fignet" stress --model "$model" --case canonical --turns "$turns" \
      >"$out/canonical-turns$turns.txt" 2>&1
    "$fignet" stress --model "$model" --case "cube at rest" --length 0.25 --turns "$turns" \
      >"$out/rest-turns$turns.txt" 2>&1
  done
  drift=(scripts/rest_drift.py --model "$model" --data data/movi-a/eval-192.h5)
  "$python" "${drift[@]}" >"$out/drift-100.txt"
  "$python" "${drift[@]}" --steps 500 --turns 2 >"$out/drift-500-turns2.txt"
  "$python" "${drift[@]}" --slide >"$out/slide.txt"
  "$python" "${drift[@]}" --release >"$out/release.txt"
  grep -h -i "translation" "$out/test-turns1.txt" "$out/test-turns2.txt" | head -n 4 || true
done

#!/usr/bin/env bash
# Every figure a model card (models/*.md) quotes, measured in one go:
#   scripts/model-card.sh MODEL.h5 [OUT_DIR]
# into OUT_DIR (default out/card/NAME/):
#   test-turns1.txt, eval.json  fignet eval on the test split (rollouts, regime split, ballistic)
#   test-turns2.txt, eval-turns2.json
#                               the same with each prediction averaged over a half turn
#   test-turns4.txt, eval-turns4.json
#                               and over quarter turns (4 predictions a step; the JSONs' per-
#                               trajectory errors pair the three scene by scene)
#   compare.txt, report.html    fignet compare on scripts/demo.sh's 4 scenes, next to native Bullet
#   stress.md, stress.txt       fignet stress, every case, network alone and the world
#   rest-turns2.txt             the resting cubes and the stacks again with 2 turns
#   curve.md, curve.png         the learning curve and its power-law fit, from MODEL.h5.log.jsonl
# Needs the README's release build and data/movi-a/test.h5 (the README's `fignet generate`
# commands). Environment: FIGNET (default build/release/tools/fignet), PYTHON (default python3,
# or /usr/bin/python3 where only that one has matplotlib, which the plot needs), JOBS (default
# 2: the measurements run in two lanes of one thread each; 1 runs them one after another).
set -euo pipefail
fignet="${FIGNET:-build/release/tools/fignet}" jobs="${JOBS:-2}" python="${PYTHON:-python3}"
[[ $# -ge 1 && $# -le 2 ]] || { echo "usage: $0 MODEL.h5 [OUT_DIR]" >&2; exit 2; }
model="$1"
[[ -f "$model" ]] || { echo "$0: no model file '$model'" >&2; exit 2; }
[[ -x "$fignet" ]] || { echo "$0: no fignet tool at '$fignet' (build the release preset)" >&2; exit 2; }
test_split=data/movi-a/test.h5
[[ -f "$test_split" ]] || { echo "$0: $test_split is missing (the README generates it)" >&2; exit 2; }
name="$(basename "${model%.h5}")"
out="${2:-out/card/$name}"
mkdir -p "$out"
export OMP_NUM_THREADS=1

# The scenes of scripts/demo.sh (seed 3: the test split's seed), made here if absent.
scenes="$out/demo-scenes.h5"
[[ -f "$scenes" ]] || "$fignet" generate --preset movi-a --count 4 --seed 3 --out "$scenes" >/dev/null

rollouts() {
  "$fignet" eval --model "$model" --data "$test_split" --json "$out/eval.json" \
    >"$out/test-turns1.txt" 2>&1
  "$fignet" eval --model "$model" --data "$test_split" --turns 2 --no-baseline \
    --json "$out/eval-turns2.json" >"$out/test-turns2.txt" 2>&1
  "$fignet" eval --model "$model" --data "$test_split" --turns 4 --no-baseline --no-penetration \
    --no-regimes --json "$out/eval-turns4.json" >"$out/test-turns4.txt" 2>&1
}
side_by_side() {
  "$fignet" compare --model "$model" --data "$scenes" --max-scenes 4 \
    --report "$out/report.html" --json "$out/compare.json" >"$out/compare.txt" 2>&1
  "$fignet" stress --model "$model" --markdown "$out/stress.md" >"$out/stress.txt" 2>&1
  for case in "cube at rest" stacks; do
    "$fignet" stress --model "$model" --case "$case" --turns 2
  done >"$out/rest-turns2.txt" 2>&1
}
echo "== $model → $out/ (${jobs} lane(s))"
if [[ "$jobs" -ge 2 ]]; then
  rollouts & lane=$!
  side_by_side
  wait "$lane"
else
  rollouts
  side_by_side
fi

log="$model.log.jsonl"
if [[ -f "$log" ]]; then
  # One reading of the log: the table always, the plot where matplotlib is there to draw it.
  plot=(--plot "$out/curve.png")
  if ! "$python" -c "import matplotlib" 2>/dev/null; then
    # A python3 first on PATH (pyenv, a venv) may lack the Debian package the system's has.
    if [[ -z "${PYTHON:-}" ]] && /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
      python=/usr/bin/python3
    else
      plot=()
      echo "(no matplotlib: curve.png not drawn; Debian's python3-matplotlib draws it)"
    fi
  fi
  "$python" scripts/training-log.py --fit --fit-from 100k "${plot[@]}" "$log" >"$out/curve.md"
fi
grep -h -E "\) +[0-9.]+ +[0-9.]+ +[0-9.]+" "$out"/test-turns{1,2,4}.txt || true
echo "figures in $out/"

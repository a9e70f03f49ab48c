#!/usr/bin/env bash
# The training study of docs/training-study.md: several recipes trained side by side from the same
# data, seeds and sample budget, each in its own process (sharing one GPU, or the CPU), each with
# its log of losses and validation rollouts. Usage:
#   scripts/training-study.sh FIGNET OUT_DIR STEPS "name: --set k=v ..." ["name: ..." ...]
# FIGNET is the fignet command (e.g. build/release/tools/fignet, or ".gpu/run fignet"); the data
# are data/movi-a/{train,valid}.h5 (README's generate commands). Environment: DEVICE (cpu or
# cuda, default cuda), THREADS per run (default 2), BATCH (default 128), VALID_EVERY (default
# STEPS/8), SECONDS_LIMIT per run (default 0: none; a run stopped by it keeps its checkpoint).
set -euo pipefail
fignet="$1" out="$2" steps="$3"
shift 3
mkdir -p "$out"
device="${DEVICE:-cuda}" threads="${THREADS:-2}" batch="${BATCH:-128}"
valid_every="${VALID_EVERY:-$((steps / 8))}" limit="${SECONDS_LIMIT:-0}"
for variant in "$@"; do
  name="${variant%%:*}" settings="${variant#*:}"
  # shellcheck disable=SC2086  # settings are words on purpose
  OMP_NUM_THREADS="$threads" timeout --signal=TERM "${limit}" $fignet train \
    --data data/movi-a/train.h5 --valid data/movi-a/valid.h5 --preset small --device "$device" \
    --steps "$steps" --valid-every "$valid_every" --log-every 50 --checkpoint-minutes 5 \
    --set batch_size="$batch" $settings --out "$out/$name.h5" >"$out/$name.out" 2>&1 &
done
wait
for variant in "$@"; do
  name="${variant%%:*}"
  echo "== $name: $(grep -a 'per step' "$out/$name.out" || echo 'no timing line')"
  grep '"valid_translation_m"' "$out/$name.h5.log.jsonl" | tail -n 3 || true
done

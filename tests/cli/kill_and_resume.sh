#!/bin/sh
# kill -9 in the middle of `fignet generate` and `fignet train`: the output is either absent or
# whole (written to a temporary file, then renamed), a rerun works, and training resumes from
# its last checkpoint.
#   kill_and_resume.sh FIGNET WORKDIR
set -eu
fignet="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"

# generate: killed mid-run, then rerun.
"$fignet" generate --count 400 --seed 4 --out "$work/set.h5" >/dev/null 2>&1 &
pid=$!
sleep 0.5
kill -9 "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
if [ -e "$work/set.h5" ]; then
  "$fignet" graph-stats --data "$work/set.h5" --max-trajectories 1 >/dev/null
  echo "generate finished before the kill; its file reads"
else
  echo "generate killed: no output file"
fi
"$fignet" generate --count 4 --seed 4 --out "$work/set.h5" >/dev/null
echo "generate rerun: ok"

# train: a checkpoint every step, killed mid-run, then resumed to two steps past the checkpoint.
"$fignet" train --data "$work/set.h5" --preset small --set batch_size=4 --set statistics_warmup=0 \
    --threads 1 --steps 100000 \
    --checkpoint-minutes 0 --out "$work/model.h5" >/dev/null 2>&1 &
pid=$!
while [ ! -e "$work/model.h5.ckpt.h5" ]; do sleep 0.2; done
sleep 1
kill -9 "$pid"
wait "$pid" 2>/dev/null || true
step=$("$fignet" train --data "$work/set.h5" --threads 1 --resume --steps 0 \
    --out "$work/probe.h5" --checkpoint "$work/model.h5.ckpt.h5" 2>/dev/null \
    | sed -n 's/^resuming .* at step \([0-9]*\)$/\1/p')
[ -n "$step" ] || { echo "the checkpoint left by the killed run does not load"; exit 1; }
"$fignet" train --data "$work/set.h5" --threads 1 --resume --steps $((step + 2)) \
    --out "$work/model.h5" 2>/dev/null | grep "trained $((step + 2)) steps"
echo "train killed at step $step or later, resumed: ok"

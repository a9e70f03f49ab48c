#!/bin/sh
# kill -9 in the middle of `fignet generate` and `fignet train`: the output is either absent or
# whole (written to a temporary file, then renamed), a rerun works, and training resumes from
# its last checkpoint. SIGTERM in the middle of training steps: the run stops cleanly (exit 0, a
# checkpoint it names), three times (a handler that ran mid-step used to corrupt the heap now
# and then).
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
while [ ! -e "$work/model.h5.ckpt.h5" ] && kill -0 "$pid" 2>/dev/null; do sleep 0.2; done
sleep 1
kill -9 "$pid"
wait "$pid" 2>/dev/null || true
step=$("$fignet" train --data "$work/set.h5" --threads 1 --resume --steps 0 \
    --out "$work/probe.h5" --checkpoint "$work/model.h5.ckpt.h5" 2>/dev/null \
    | sed -n 's/^resuming .* at step \([0-9]*\)$/\1/p')
[ -n "$step" ] || { echo "the checkpoint left by the killed run does not load"; exit 1; }
"$fignet" train --data "$work/set.h5" --threads 1 --resume --steps $((step + 2)) \
    --out "$work/model.h5" 2>/dev/null | grep -E "trained 2 steps( \(step $step to $((step + 2))\))?;"

# train: SIGTERM mid-step, three times at different moments of the steps.
for delay in 0.3 0.7 1.1; do
  rm -f "$work"/stopped.h5*
  "$fignet" train --data "$work/set.h5" --preset small --set batch_size=4 \
      --set statistics_warmup=0 --threads 1 --steps 100000 --log-every 1 \
      --out "$work/stopped.h5" >"$work/stopped.out" 2>&1 &
  pid=$!
  # Steps are under way once the log has its first line.
  while [ ! -s "$work/stopped.h5.log.jsonl" ] && kill -0 "$pid" 2>/dev/null; do sleep 0.1; done
  sleep "$delay"
  kill -TERM "$pid"
  status=0
  wait "$pid" || status=$?
  [ "$status" -eq 0 ] || { echo "SIGTERM after $delay s: exit status $status"; cat "$work/stopped.out"; exit 1; }
  grep -q "^stopped at step [0-9]*; checkpoint" "$work/stopped.out" ||
    { echo "SIGTERM after $delay s: no stop line"; cat "$work/stopped.out"; exit 1; }
done
echo "train stopped by SIGTERM three times: ok"
echo "train killed at step $step or later, resumed: ok"

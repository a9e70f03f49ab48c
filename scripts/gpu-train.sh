#!/usr/bin/env bash
# Trains up to three runs side by side on one GPU machine for a fixed time, each ended by SIGINT
# (which writes its checkpoint), and copies what each run needs to continue into one folder.
# Meant for a GPU lent for minutes without the Debian packages (docs/gpu.md): run it there, in the
# repository root, with the bundle of scripts/bundle-for-gpu.sh.
#   scripts/gpu-train.sh SECONDS DEST 'RUN 1 ARGS' ['RUN 2 ARGS' ['RUN 3 ARGS']]
# Each RUN ARGS is `fignet train`'s arguments without --threads and --device; --out names the
# run. For each run DEST receives its checkpoint under its own name (NAME.h5.ckpt.h5 for --out
# NAME.h5) and NAME.tar (its model, log and console output):
# two files per run, so that three runs stay within what a device call returns (8 files).
# SECONDS is the training's share of the call: leave ~60 s of the call's limit for unpacking,
# data, the CUDA tests and the checkpoints (a run stopped during a validation finishes it first).
# Datasets under data/ that a run names and that are missing are generated from their seeds
# (the commands of the runs' READMEs), so only the bundle and the checkpoints need to travel.
# Environment: BUNDLE (a .tar.xz of the bundle, unpacked when .gpu/ is absent; default
# .gpucarry/bundle.tar.xz), FIGNET (default .gpu/run fignet), DEVICE (default cuda), TEST_CUDA
# (1: run the CUDA tests first; default 1).
set -uo pipefail
[[ $# -ge 3 && $# -le 5 ]] || {
  echo "usage: $0 SECONDS DEST 'TRAIN ARGS' ['TRAIN ARGS' ['TRAIN ARGS']]" >&2
  exit 2
}
seconds="$1" dest="$2"
shift 2
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "$0: SECONDS must be a whole number, not '$seconds'" >&2; exit 2; }
bundle="${BUNDLE:-.gpucarry/bundle.tar.xz}" device="${DEVICE:-cuda}"
start=$(date +%s)
elapsed() { echo "$(($(date +%s) - start)) s"; }

# The bundle, unless a build is named or already unpacked.
if [[ -z "${FIGNET:-}" && ! -x .gpu/run ]]; then
  [[ -f "$bundle" ]] || { echo "$0: no .gpu/ and no bundle '$bundle'" >&2; exit 2; }
  tar xJf "$bundle" || { echo "$0: could not unpack '$bundle'" >&2; exit 1; }
fi
read -r -a fignet <<<"${FIGNET:-.gpu/run fignet}"
[[ "$device" == cpu ]] || nvidia-smi -L

# Each run's --out and the datasets it names.
outs=() datasets=()
for args in "$@"; do
  read -r -a words <<<"$args"
  out=""
  for ((i = 0; i < ${#words[@]}; ++i)); do
    case "${words[i]}" in
    --out) out="${words[i + 1]:-}" ;;
    data/*.h5) datasets+=("${words[i]}") ;;
    --threads | --device) echo "$0: leave ${words[i]} out of the runs' arguments (set here)" >&2; exit 2 ;;
    esac
  done
  [[ -n "$out" ]] || { echo "$0: no --out in '$args'" >&2; exit 2; }
  outs+=("$out")
done

# Missing datasets from their seeds, all at once.
generate_arguments() {
  case "$1" in
  data/movi-a/train.h5) echo "--preset movi-a --count 1500 --seed 1" ;;
  data/movi-a/valid.h5) echo "--preset movi-a --count 100 --seed 2" ;;
  data/movi-a/test.h5) echo "--preset movi-a --count 100 --seed 3" ;;
  data/movi-a-stacks/train.h5)
    echo "--preset movi-a --stacks 2 --min-objects 1 --max-objects 5 --count 500 --seed 21" ;;
  data/movi-a-tall-stacks/train.h5)
    echo "--preset movi-a --stacks 2 --min-stack-levels 2 --max-stack-levels 5 --min-objects 1" \
      "--max-objects 5 --count 500 --seed 31" ;;
  *) return 1 ;;
  esac
}
((${#datasets[@]} > 0)) && mapfile -t datasets < <(printf '%s\n' "${datasets[@]}" | sort -u)
for data in "${datasets[@]}"; do
  [[ -f "$data" ]] && continue
  generate="$(generate_arguments "$data")" || {
    echo "$0: '$data' is missing and its seed is not known here: carry it" >&2
    exit 2
  }
  mkdir -p "$(dirname "$data")"
  read -r -a generate_words <<<"$generate"
  "${fignet[@]}" generate "${generate_words[@]}" --out "$data" >/dev/null &
done
wait
((${#datasets[@]} == 0)) || md5sum "${datasets[@]}" || exit 1
echo "data ready at $(elapsed)"

if [[ "$device" != cpu && "${TEST_CUDA:-1}" == 1 ]]; then
  timeout 120 "${fignet[0]}" test_cuda 2>&1 | tail -3
  echo "CUDA tests done at $(elapsed)"
fi

# The runs side by side, the cores shared out, each stopped by SIGINT after SECONDS.
threads=$(($(nproc) / $#))
((threads > 0)) || threads=1
logs=()
trap 'rm -f "${logs[@]}"' EXIT # each console is copied beside its run below
for ((r = 0; r < $#; ++r)); do
  read -r -a words <<<"${@:r+1:1}"
  log="$(mktemp)"
  logs+=("$log")
  OMP_NUM_THREADS=$threads timeout -k 120 -s INT "$seconds" "${fignet[@]}" train "${words[@]}" \
    --threads "$threads" --device "$device" >"$log" 2>&1 &
done
wait
echo "training done at $(elapsed)"

# What each run needs to continue, two files per run.
mkdir -p "$dest"
status=0
for ((r = 0; r < ${#outs[@]}; ++r)); do
  out="${outs[r]}" name="$(basename "${outs[r]}" .h5)"
  tail -n 4 "${logs[r]}"
  cp "${logs[r]}" "$(dirname "$out")/$name.console.txt"
  if [[ ! -f "$out.ckpt.h5" ]]; then
    echo "$0: run '$out' left no checkpoint (its console: above)" >&2
    status=1
    continue
  fi
  cp "$out.ckpt.h5" "$dest/$(basename "$out").ckpt.h5"
  files=("$name.console.txt" "$name.h5.log.jsonl")
  [[ -f "$out" ]] && files+=("$name.h5")
  tar cf "$dest/$name.tar" -C "$(dirname "$out")" "${files[@]}"
done
ls -la "$dest"
exit $status

#!/usr/bin/env bash
# Train face models on one GPU, several recipes side by side, from the training clips packed into one file.
#
#   scripts/face-gpu.sh PACK.npz OUT MINUTES RECIPES
#
# Runs from any folder. PACK.npz is `python -m talkingface.train.packed`'s file (the dataset's training clips, the
# faces compressed), so the machine needs neither the corpus nor the speech tools: only this tree, PyTorch and numpy.
# RECIPES is a file of recipes, one a line: a name, then train.train's options (# starts a comment; paths such as
# models/checkpoint.pt are the repository's; scripts/face-gpu-first.txt is the first run's). Each trains for MINUTES
# and is packed into OUT/<recipe>.tar: its final.pt without the optimiser (the model, its configs and arguments, for
# lip_closure, head_motion, evaluate and export on the CPU) and its log. A recipe still running two minutes past its
# budget is stopped (SIGTERM: it saves its checkpoint, which is packed instead); one that leaves no model (a wrong
# option: its log says) is named at the end, and the script exits 1 after packing the others. DEVICE=cpu runs it on
# the CPU (slowly: to try a setup); PYTHON names the interpreter (the machine's python3 by default).
set -euo pipefail
if [[ $# -ne 4 ]]; then
  echo "usage: scripts/face-gpu.sh PACK.npz OUT MINUTES RECIPES" >&2
  exit 2
fi
for f in "$1" "$4"; do
  [[ -f $f && -r $f ]] || { echo "face-gpu.sh: cannot read $f" >&2; exit 2; }
done
mkdir -p "$2"
# Paths as given, from wherever it is run; the toolkit and the recipes' paths (models/...) from the repository root.
pack=$(realpath "$1") out=$(realpath "$2") minutes=$3 recipes=$(realpath "$4")
cd "$(dirname "${BASH_SOURCE[0]}")/.."
device=${DEVICE:-cuda} python=${PYTHON:-python3}
export PYTHONPATH=$PWD/training/src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT # the full checkpoints (with the optimiser's state) stay behind otherwise

train() {  # name, then train.train's options
  local name=$1
  shift
  timeout "$(awk "BEGIN { print int($minutes * 60 + 120) }")" "$python" -m talkingface.train.train --packed "$pack" \
    --out "$work/$name" --device "$device" --threads 2 --minutes "$minutes" --checkpoint-every 500 "$@" \
    >"$work/$name.log" 2>&1 || true
  local ck=$work/$name/final.pt
  [[ -f $ck ]] || ck=$work/$name/checkpoint.pt
  if [[ -f $ck ]]; then
    "$python" -c 'import sys, torch; ck = torch.load(sys.argv[1], map_location="cpu", weights_only=False); ck.pop("optimizer", None); torch.save(ck, sys.argv[2])' \
      "$ck" "$work/$name/model.pt"
  fi
  local what=("$name.log")
  [[ -f $work/$name/model.pt ]] && what+=("$name") || echo "$name" >>"$work/failed"
  tar -C "$work" -cf "$out/$name.tar" --exclude checkpoint.pt --exclude final.pt "${what[@]}"
}

set -f # the options are words, never file patterns
while read -r name options || [[ -n $name ]]; do # the last line without its newline too
  [[ -z $name || $name == \#* ]] && continue
  # shellcheck disable=SC2086  # the options are words
  train "$name" ${options%%#*} &
done <"$recipes"
set +f
wait
for f in "$work"/*.log; do echo "== $f"; grep -v '^step' "$f" | tail -n 3; grep '^step' "$f" | tail -n 1 || true; done
if [[ -s $work/failed ]]; then
  echo "face-gpu.sh: no model from: $(tr '\n' ' ' <"$work/failed")(their logs are in $out)" >&2
  exit 1
fi

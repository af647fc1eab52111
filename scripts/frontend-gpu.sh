#!/usr/bin/env bash
# Train speech front-ends on one GPU, six recipes side by side (from scratch or from the shipped front-end, with and
# without --consistency), from one packed speech bank.
#
#   scripts/frontend-gpu.sh BANK.npz OUT MINUTES [RECIPES]
#
# BANK.npz is `python -m talkingface.frontend.bank`'s file (the training speech and the corpus's val and test clips),
# so the machine needs neither the speech set nor the corpus: only this tree, PyTorch and numpy. A short run first
# measures the speed (and fails in seconds where the setup is broken); then each recipe trains for MINUTES on batches
# of 256 crops, with its front-end kept about five times on the way (--snapshots, to be chosen on val afterwards),
# and is packed into OUT/<recipe>.tar with its log (the optimiser's checkpoint stays behind). A recipe still running
# two minutes past its budget is stopped, its snapshots so far kept. Runs on the CPU too (slowly): DEVICE=cpu
# (PYTHON names the interpreter: scripts/py's venv here, the machine's python3 by default). EVERY=N keeps a snapshot
# every N steps instead, without the short run (where the time on the machine is short and the setup was tried here).
# RECIPES, where given, is a file of recipes, one a line: a name, then frontend.train's options (# starts a comment);
# scripts/frontend-gpu-timbre.txt is the second run's. Without it, the first run's six below.
set -euo pipefail
bank=$1 out=$2 minutes=$3 recipes=${4:-}
device=${DEVICE:-cuda} python=${PYTHON:-python3}
export PYTHONPATH=training/src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
if [[ -n $recipes && ! -r $recipes ]]; then
  echo "frontend-gpu.sh: no recipes file $recipes" >&2
  exit 2
fi
work=$(mktemp -d)
mkdir -p "$out"

train() {  # name, then frontend.train's options
  local name=$1
  shift
  timeout "$(awk "BEGIN { print int($minutes * 60 + 120) }")" "$python" -m talkingface.frontend.train --packed "$bank" \
    --out "$work/$name" --device "$device" --threads 2 --batch 256 --minutes "$minutes" --eval-every "$every" --snapshots \
    "$@" >"$work/$name.log" 2>&1 || true
  tar -C "$work" -cf "$out/$name.tar" --exclude checkpoint.pt "$name" "$name.log"
}

if [[ -n ${EVERY:-} ]]; then
  every=$EVERY
  echo "a snapshot every $every steps (EVERY; no smoke run)"
else
  "$python" -m talkingface.frontend.train --packed "$bank" --out "$work/smoke" --device "$device" --threads 2 \
    --batch 256 --steps 200 --eval-every 100 --consistency 1 2>&1 | tee "$work/smoke.log"
  rate=$(grep -o '[0-9.]* steps/s' "$work/smoke.log" | tail -n 1 | cut -d' ' -f1)
  every=$(awk "BEGIN { e = int($rate * $minutes * 60 / 5 / 100) * 100; print (e < 100 ? 100 : e) }")
  echo "smoke run: $rate steps/s (two views); a snapshot every $every steps"
fi

if [[ -n $recipes ]]; then
  set -f # the options are words, never file patterns
  while read -r name options; do
    [[ -z $name || $name == \#* ]] && continue
    # shellcheck disable=SC2086  # the options are words
    train "$name" ${options%%#*} &
  done <"$recipes"
  set +f
else
  train scratch --lr 2e-3 &
  train scratch-consistent --lr 2e-3 --consistency 1 &
  train tuned --lr 3e-4 --init models/checkpoint.pt &
  train tuned-consistent --lr 3e-4 --init models/checkpoint.pt --consistency 1 &
  train scratch-consistent3 --lr 2e-3 --consistency 3 &
  train tuned-consistent3 --lr 3e-4 --init models/checkpoint.pt --consistency 3 &
fi
wait
for f in "$work"/*.log; do echo "== $f"; tail -n 4 "$f"; done

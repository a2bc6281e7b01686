#!/usr/bin/env bash
# Trains the default configuration on every clip of the project (the shared folder's ten, and
# the MANN dog walk at its own 60 fps as well), keeps the checkpoints at STEPS (default every
# 3 000 steps from 5 000, and the last), and scores each kept checkpoint with `sinmdm eval`
# (20 samples of twice the clip, default sampling, seed 0). The data behind the adaptive
# default's candidate rules: how coverage, diversity, replay and jitter move along a run, and
# what each clip's facts (length, motion span, own diversity) say beforehand.
#
# Usage: lab/scripts/checkpoint_sweep.sh SHARED_BVH_DIR [OUT_DIR]
#   OUT_DIR  runs, kept checkpoints, models and eval JSON (default out/checkpoint_sweep); a
#            finished clip is skipped, so the script can be stopped and run again.
# STEPS (environment): the steps to keep, space-separated. CLIPS: the names to run (default all).
# Pause any other training or benchmark while this runs: the times are wall-clock.
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=${1:?usage: checkpoint_sweep.sh SHARED_BVH_DIR [OUT_DIR]}
out=${2:-out/checkpoint_sweep}
steps=${STEPS:-"5000 8000 11000 14000 17000"}
mkdir -p "$out"
train=target/release/sinmdm-train
export_bin=target/release/sinmdm-export
sinmdm=target/release/sinmdm

# name : clip file : extra sinmdm-train arguments
source lab/scripts/project_clips.sh
all=()
for name in $(printf '%s\n' "${!project_clip_files[@]}" | sort); do
  all+=("$name:${project_clip_files[$name]}:")
done
all+=("dog_walk_mann_60fps:${project_clip_files[dog_walk_mann]}:--fps clip")

step_name() { printf 'step-%08d' "$1"; }

for entry in "${all[@]}"; do
  IFS=: read -r name clip extra <<<"$entry"
  if [ -n "${CLIPS:-}" ] && [[ " $CLIPS " != *" $name "* ]]; then continue; fi
  clip=$shared/$clip
  run=$out/$name
  kept=$out/$name.kept
  mkdir -p "$kept"
  # shellcheck disable=SC2086
  [ -f "$out/$name.facts" ] || "$train" "$clip" --dry-run $extra >"$out/$name.facts" 2>&1 || true
  if [ ! -f "$out/$name.trained" ]; then
    start=$(date +%s)
    if [ -f "$run/latest" ]; then
      "$train" --resume --out "$run" >"$out/$name.log" 2>&1 &
    else
      # shellcheck disable=SC2086
      "$train" "$clip" --out "$run" $extra >"$out/$name.log" 2>&1 &
    fi
    pid=$!
    # The trainer keeps only its newest checkpoints: copy the wanted ones as they appear.
    while kill -0 "$pid" 2>/dev/null; do
      for s in $steps; do
        d=$run/checkpoints/$(step_name "$s")
        if [ -d "$d" ] && [ ! -d "$kept/$(step_name "$s")" ]; then
          cp -r "$d" "$kept/.partial" && mv "$kept/.partial" "$kept/$(step_name "$s")"
        fi
      done
      sleep 3
    done
    wait "$pid"
    for s in $steps; do
      d=$run/checkpoints/$(step_name "$s")
      [ -d "$d" ] && [ ! -d "$kept/$(step_name "$s")" ] && cp -r "$d" "$kept/$(step_name "$s")"
    done
    echo $(( $(date +%s) - start )) >"$out/$name.trained"
  fi
  for s in $steps; do
    ck=$kept/$(step_name "$s")
    [ -d "$ck" ] || continue
    model=$out/$name.$s.onnx
    json=$out/$name.$s.json
    [ -f "$model" ] || "$export_bin" "$ck" -o "$model" >/dev/null
    [ -f "$json" ] || "$sinmdm" eval -m "$model" --clip "$clip" --samples 20 --seed 0 \
      --quiet --json "$json" >/dev/null
  done
  echo "$name done: $(cat "$out/$name.trained") s"
done

#!/usr/bin/env bash
# Scores, on the replay measure, motion made from each clip that is not a copy of it (the clip
# backwards, re-timed, its hold) beside the shipped model's samples where there is one:
# lab/scripts/replay_floor.py says what each column is.
#
# Usage: lab/scripts/replay_floor.sh SHARED_BVH_DIR
# CLIPS (environment): the clip names to score, space-separated (default: the ten of
#   lab/scripts/project_clips.sh); NAME=PATH scores a clip from outside the project under NAME.
# OUT (environment): where the runs and features go (default out/replay_floor). Each clip's
# features come from a two-step training run on it (it only gives `sinmdm encode` the skeleton's
# layout); a clip already there is not run again.
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=${1:?usage: replay_floor.sh SHARED_BVH_DIR}
out=${OUT:-out/replay_floor}
mkdir -p "$out"
source lab/scripts/project_clips.sh
config=$out/two_steps.yaml
# The default without the rule, for two steps: enough to export a model with the clip's layout.
sed -e 's/^  steps: 17000$/  steps: 2/' -e 's/^  warmup_steps: 500$/  warmup_steps: 1/' \
  -e '/^from_clip:/,$d' configs/default.yaml >"$config"
grep -q '^  steps: 2$' "$config" || { echo "replay_floor: configs/default.yaml changed its steps line" >&2; exit 1; }
rows=()
for name in ${CLIPS:-$(printf '%s\n' "${!project_clip_files[@]}" | sort)}; do
  if [[ $name == *=* ]]; then
    clip=${name#*=}
    name=${name%%=*}
  else
    clip=$shared/${project_clip_files[$name]:?unknown clip $name}
  fi
  base=$out/$name
  if [ ! -f "$base.clip.json" ]; then
    rm -rf "$base.run"
    target/release/sinmdm-train "$clip" --config "$config" --out "$base.run" >"$base.log" 2>&1
    target/release/sinmdm-export "$base.run" -o "$base.onnx" >/dev/null 2>>"$base.log"
    target/release/sinmdm encode "$clip" -m "$base.onnx" -o "$base.clip.json" >/dev/null 2>>"$base.log"
  fi
  row="$name=$base.clip.json"
  shipped=onnx-models/$name.onnx
  if [ -f "$shipped" ]; then
    [ -f "$base.samples.json" ] || target/release/sinmdm eval -m "$shipped" --clip "$clip" \
      --samples 20 --seed 0 --quiet --features-json "$base.samples.json" >/dev/null 2>>"$base.log"
    row+=",$base.samples.json"
  fi
  rows+=("$row")
done
.venv/bin/python lab/scripts/replay_floor.py "${rows[@]}"

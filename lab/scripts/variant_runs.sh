#!/usr/bin/env bash
# Trains one variant of the training (a config file and/or sinmdm-train flags) on chosen clips of
# the project and scores each with `sinmdm eval` (20 samples of twice the clip, default sampling,
# seed 0): the runs behind the adaptive default's candidate rules that are not along one run.
#
# Usage: lab/scripts/variant_runs.sh SHARED_BVH_DIR VARIANT [CONFIG.yaml|-] [FLAGS...]
#   VARIANT   a name for the variant; runs go to out/variants/CLIP.VARIANT (+ .onnx, .json, .log,
#             .trained holding the trainer's wall seconds). A finished clip is skipped.
#   CONFIG    a training config (- for none, so sinmdm-train chooses the default)
# CLIPS (environment): the clip names to run, space-separated (default: all eleven); NAME=PATH
#   runs a clip from outside the project under NAME.
# Pause any other training or benchmark while this runs: the times are wall-clock.
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=${1:?usage: variant_runs.sh SHARED_BVH_DIR VARIANT [CONFIG|-] [FLAGS...]}
variant=${2:?variant name}
config=${3:--}
shift 3 || shift $#
out=${OUT:-out/variants}
mkdir -p "$out"
train=target/release/sinmdm-train
export_bin=target/release/sinmdm-export
sinmdm=target/release/sinmdm

source lab/scripts/project_clips.sh
# The dog walk learned at its own 60 fps (--fps clip, below).
project_clip_files[dog_walk_mann_60fps]=${project_clip_files[dog_walk_mann]}
clips=${CLIPS:-"${!project_clip_files[*]}"}
for name in $clips; do
  if [[ $name == *=* ]]; then
    clip=${name#*=}
    name=${name%%=*}
  else
    clip=$shared/${project_clip_files[$name]:?unknown clip $name}
  fi
  extra=()
  [ "$name" = dog_walk_mann_60fps ] && extra=(--fps clip)
  [ "$config" != - ] && extra+=(--config "$config")
  base=$out/$name.$variant
  if [ ! -f "$base.trained" ]; then
    rm -rf "$base"
    start=$(date +%s.%N)
    "$train" "$clip" --out "$base" "${extra[@]}" "$@" >"$base.log" 2>&1
    echo "$(date +%s.%N) - $start" | bc >"$base.trained"
  fi
  [ -f "$base.onnx" ] || "$export_bin" "$base" -o "$base.onnx" >/dev/null
  [ -f "$base.json" ] || "$sinmdm" eval -m "$base.onnx" --clip "$clip" --samples 20 --seed 0 \
    --quiet --json "$base.json" >/dev/null
  python3 - "$base.json" "$(cat "$base.trained")" "$name" "$variant" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); r = d["report"]
print(f"{sys.argv[3]} {sys.argv[4]}: {float(sys.argv[2]):.0f} s, coverage {r['coverage']['mean']:.1f}, "
      f"diversity {r['global_diversity']['mean']:.3f}, clip intra {r['clip_intra_diversity']:.3f}, "
      f"replay {d['replay']['mean_seconds']:.2f} s, jitter {d['feet']['raw']['jitter_ratio']:.2f}x")
PY
done

#!/usr/bin/env bash
# Scores models of the same clips with the world and the heading-relative root side by side:
# coverage and global diversity on the whole metric (which includes the root joint's rotation,
# meant differently by the two layouts) and on the body alone (the joints below the root, which
# `sinmdm eval` reports as body_report), replay, jitter and foot skating (SPEC section 9). 20 samples of twice the clip's
# length, default sampling, eval seeds 0-2 (mean and standard error).
#
# Usage: lab/scripts/root_layout_table.sh WORLD_DIR HEADING_DIR [SHARED_BVH_DIR]
#   WORLD_DIR, HEADING_DIR  NAME.onnx models of each layout, as lab/scripts/train_table.sh
#                           makes them (TRAIN_ARGS="--root-layout world" or "--root-layout heading");
#                           a clip is scored where both folders have its model, into
#                           DIR/NAME.layouts.seedS.json (kept: a second run only prints)
#   SHARED_BVH_DIR          the shared clip folder (the MANN dog and the zombie walk)
set -euo pipefail
cd "$(dirname "$0")/../.."
world=$1
heading=$2
shared=${3:-}
sinmdm=target/release/sinmdm
[ -x "$sinmdm" ] || cargo build --release -p sinmdm-cli --quiet

clips=("human_walk_cmu:tests/data/bvh/human_walk_cmu_131_01.bvh"
       "human_hop_cmu:tests/data/bvh/human_hop_cmu_131_03.bvh"
       "fox_survey_khronos:tests/data/bvh/fox_survey_khronos.bvh"
       "human_dance_rokoko:tests/data/bvh/human_dance_rokoko_jesse.bvh")
if [ -n "$shared" ]; then
  clips+=("dog_walk_mann:$shared/dog_walk_mann_d1_047z_kan01_004.bvh"
          "human_zombie_walk_fair:$shared/human_zombie_walk_fair.bvh")
fi
rows=()
for entry in "${clips[@]}"; do
  IFS=: read -r name clip <<<"$entry"
  [ -f "$world/$name.onnx" ] && [ -f "$heading/$name.onnx" ] || continue
  for dir in "$world" "$heading"; do
    for seed in 0 1 2; do
      json="$dir/$name.layouts.seed$seed.json"
      [ -f "$json" ] || "$sinmdm" eval -m "$dir/$name.onnx" --clip "$clip" --samples 20 \
        --seed "$seed" --quiet --json "$json" >/dev/null
    done
  done
  rows+=("$name")
done

python3 - "$world" "$heading" "${rows[@]}" <<'PY'
import json, pathlib, statistics, sys
world, heading, names = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3:]


def stat(folder, name, pick):
    values = [pick(json.loads((folder / f"{name}.layouts.seed{s}.json").read_text()))
              for s in range(3)]
    return statistics.mean(values), statistics.stdev(values) / len(values) ** 0.5


print("| clip | root | coverage | global diversity | body coverage | body global diversity | body: clip's own intra diversity | replay (s) | jitter x clip | skating, planted (clip) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for name in names:
    for label, folder in (("world", world), ("heading", heading)):
        cells = [
            stat(folder, name, lambda d: d["report"]["coverage"]["mean"]),
            stat(folder, name, lambda d: d["report"]["global_diversity"]["mean"]),
            stat(folder, name, lambda d: d["body_report"]["coverage"]["mean"]),
            stat(folder, name, lambda d: d["body_report"]["global_diversity"]["mean"]),
        ]
        clip_intra = json.loads((folder / f"{name}.layouts.seed0.json").read_text())["body_report"]["clip_intra_diversity"]
        replay = stat(folder, name, lambda d: d["replay"]["mean_seconds"])
        jitter = stat(folder, name, lambda d: d["feet"]["raw"]["jitter_ratio"])
        skating = stat(folder, name, lambda d: d["feet"]["planted"]["mean"]["skating_ratio"])
        clip_skating = json.loads((folder / f"{name}.layouts.seed0.json").read_text())["feet"]["clip"]["skating_ratio"]
        print(f"| {name if label == 'world' else ''} | {label} | "
              f"{cells[0][0]:.1f} ± {cells[0][1]:.1f} | {cells[1][0]:.3f} ± {cells[1][1]:.3f} | "
              f"{cells[2][0]:.1f} ± {cells[2][1]:.1f} | {cells[3][0]:.3f} ± {cells[3][1]:.3f} | "
              f"{clip_intra:.3f} | {replay[0]:.2f} | {jitter[0]:.2f} | "
              f"{skating[0]:.3f} ({clip_skating:.3f}) |")
PY

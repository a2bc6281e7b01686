#!/usr/bin/env bash
# Trains the default configuration (configs/default.yaml) on each of the project's clips, one
# after another, scores every model with `sinmdm eval` (20 samples of twice the clip's length,
# default sampling, seed 0) and prints one Markdown table: training time, coverage, diversity,
# intra-diversity difference, replay (the samples' longest verbatim copy of the clip) and jitter
# against the clip's, and what the trainer did about non-finite steps (none, in a healthy run).
# Twenty samples are a small crowd (one seed's coverage can be 1-3 points off), so each model is
# also scored with seeds 1-4 and the table gives the mean of the five and its standard error
# beside seed 0's figures.
#
# Usage: lab/scripts/train_table.sh [OUT_DIR] [SHARED_BVH_DIR]
#   OUT_DIR         runs, models and eval JSON (default out/train_table); finished runs are kept
#                   and not trained again, an interrupted one resumes
#   SHARED_BVH_DIR  the shared clip folder, if you have it: adds the MANN dog walk (60 fps,
#                   learned at 30 fps and at its own rate) and the zombie walk
# TRAIN_ARGS (environment) adds sinmdm-train arguments to every new run, for example
# TRAIN_ARGS="--root-layout world" or "--root-layout heading" for one root layout on every clip
# (the default, auto, gives travelling clips the heading root and the rest the world root).
# Pause any other training or benchmark while this runs: the times are wall-clock on this machine.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-out/train_table}
shared=${2:-}
mkdir -p "$out"
train=target/release/sinmdm-train
sinmdm=target/release/sinmdm
[ -x "$train" ] || cargo build --release -p sinmdm-train --quiet
[ -x "$sinmdm" ] || cargo build --release -p sinmdm-cli --quiet

# name : clip : extra sinmdm-train arguments
clips=("human_walk_cmu:tests/data/bvh/human_walk_cmu_131_01.bvh:"
       "human_hop_cmu:tests/data/bvh/human_hop_cmu_131_03.bvh:"
       "fox_survey_khronos:tests/data/bvh/fox_survey_khronos.bvh:"
       "human_dance_rokoko:tests/data/bvh/human_dance_rokoko_jesse.bvh:")
if [ -n "$shared" ]; then
  dog=$shared/dog_walk_mann_d1_047z_kan01_004.bvh
  clips=("human_zombie_walk_fair:$shared/human_zombie_walk_fair.bvh:" "${clips[@]}"
         "dog_walk_mann:$dog:" "dog_walk_mann_60fps:$dog:--fps clip")
fi

for entry in "${clips[@]}"; do
  IFS=: read -r name clip extra <<<"$entry"
  run="$out/$name"
  model="$out/$name.onnx"
  if [ ! -f "$model" ]; then
    if [ -f "$run/latest" ]; then
      "$train" --resume --out "$run" --export "$model"
    else
      # shellcheck disable=SC2086
      "$train" "$clip" --out "$run" --export "$model" $extra ${TRAIN_ARGS:-}
    fi
  fi
  for seed in 0 1 2 3 4; do
    json="$out/$name.seed$seed.json"
    [ "$seed" = 0 ] && json="$out/$name.json"
    [ -f "$json" ] || "$sinmdm" eval -m "$model" --clip "$clip" --samples 20 --seed "$seed" \
      --quiet --json "$json" >/dev/null
  done
done

python3 - "$out" <<'PY'
import json, pathlib, statistics, sys
out = pathlib.Path(sys.argv[1])


def five_seeds_of(name, pick):
    """Mean and standard error over eval seeds 0-4 of a figure picked from each eval file."""
    files = [out / f"{name}.json"] + [out / f"{name}.seed{s}.json" for s in range(1, 5)]
    values = [pick(json.loads(f.read_text())) for f in files]
    return statistics.mean(values), statistics.stdev(values) / len(values) ** 0.5


def five_seeds(name, key):
    """Mean and standard error of a score of the report over eval seeds 0-4."""
    return five_seeds_of(name, lambda f: f["report"][key]["mean"])


print("| clip | frames (fps) | steps | training time | coverage | global diversity | coverage, seeds 0-4 | global diversity, seeds 0-4 | intra diff | clip's own intra diversity | replay (s), seeds 0-4 | jitter x clip | non-finite steps | s per sample |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for path in sorted(p for p in out.glob("*.json") if ".seed" not in p.name):
    d = json.loads(path.read_text())
    run = out / path.stem
    latest = (run / "latest").read_text().strip()
    state = json.loads((run / latest / "state.json").read_text())
    recovery = state.get("recovery", {"skipped_steps": 0, "rollbacks": 0})
    events = "none" if recovery["skipped_steps"] == 0 else \
        f"{recovery['skipped_steps']} skipped, {recovery['rollbacks']} roll-backs"
    r = d["report"]
    fps = state["clip"]["layout"]["fps"]
    replay = five_seeds_of(path.stem, lambda f: f["replay"]["mean_seconds"])
    print(f"| {path.stem} | {state['clip']['frames']} ({fps:g}) | {state['step']} | "
          f"{state['elapsed_seconds'] / 60:.1f} min | {r['coverage']['mean']:.1f} | "
          f"{r['global_diversity']['mean']:.3f} | "
          "{:.1f} ± {:.1f} | {:.3f} ± {:.3f} | ".format(
              *five_seeds(path.stem, "coverage"), *five_seeds(path.stem, "global_diversity"))
          + f"{r['intra_diversity_diff']:.3f} | "
          f"{r['clip_intra_diversity']:.3f} | "
          "{:.2f} ± {:.2f} | ".format(*replay)
          + f"{d['feet']['raw']['jitter_ratio']:.2f} | {events} | "
          f"{d['sampling_seconds'] / d['samples']:.3f} |")
PY

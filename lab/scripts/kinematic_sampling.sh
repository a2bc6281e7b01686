#!/usr/bin/env bash
# How the sampling alone moves the shipped models' kinematic fidelity (`sinmdm eval`: 20 samples
# of twice the clip's length, seed 0): the default (50 ancestral steps), all 1 000 steps, and
# the two deterministic samplers, which add no noise after the first step. One Markdown row per
# model and setting: nearly still share (the clip's), speed p25/p50/p90 over the clip's, the
# speed and acceleration distances, coverage, global diversity and jitter (raw samples).
# Usage: lab/scripts/kinematic_sampling.sh [OUT_DIR]   (the JSON of every run is kept there)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-out/kinematic_sampling}
mkdir -p "$out"
sinmdm=target/release/sinmdm
[ -x "$sinmdm" ] || cargo build --release -p sinmdm-cli --quiet
settings=("ancestral:50" "ancestral:all" "ddim:50" "dpm2m:20")
models=("fox_survey_khronos:fox_survey_khronos" "human_dance_rokoko:human_dance_rokoko_jesse"
        "human_zombie_walk_fair:human_zombie_walk_fair" "human_walk_cmu:human_walk_cmu_131_01"
        "human_hop_cmu:human_hop_cmu_131_03")
for pair in "${models[@]}"; do
  model=${pair%%:*}
  clip=${pair##*:}
  for setting in "${settings[@]}"; do
    sampler=${setting%%:*}
    steps=${setting##*:}
    json="$out/${model}_${sampler}_${steps}.json"
    [ -f "$json" ] || "$sinmdm" eval -m "onnx-models/$model.onnx" --clip "tests/data/bvh/$clip.bvh" \
      --samples 20 --steps "$steps" --sampler "$sampler" --quiet --json "$json" >/dev/null
  done
done
.venv/bin/python - "$out" "${models[@]}" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
print("| model | sampler | steps | still % (clip) | speed p25 / p50 / p90 | speed / accel. distance | coverage | global div. | jitter x clip |")
print("|---|---|---|---|---|---|---|---|---|")
for pair in sys.argv[2:]:
    model = pair.split(":")[0]
    for setting in ["ancestral_50", "ancestral_all", "ddim_50", "dpm2m_20"]:
        d = json.loads((out / f"{model}_{setting}.json").read_text())
        k, c = d["kinematics"]["raw"], d["kinematics"]["clip"]
        ratios = " / ".join(f"{r:.2f}" for r in k["speed_ratios"])
        print(f"| {model} | {d['sampler']} | {d['steps']} | {100 * k['still_share']:.1f} ({100 * c['still_share']:.1f}) "
              f"| {ratios} | {k['speed_distance']:.2f} / {k['acceleration_distance']:.2f} "
              f"| {d['report']['coverage']['mean']:.1f} | {d['report']['global_diversity']['mean']:.3f} "
              f"| {d['feet']['raw']['jitter_ratio']:.2f} |")
PY

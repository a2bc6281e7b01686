#!/usr/bin/env bash
# Scores sampling methods and step counts against 1 000 ancestral steps with `sinmdm eval`
# (20 samples of twice the clip's length, seed 0) on the shipped models, and prints one
# Markdown table per model: coverage, global diversity, jitter and seconds per sample.
# Usage: lab/scripts/sampler_table.sh [OUT_DIR]   (the JSON of every run is kept there)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-out/sampler_table}
mkdir -p "$out"
sinmdm=target/release/sinmdm
[ -x "$sinmdm" ] || cargo build --release -p sinmdm-cli --quiet
configs=("ancestral 1000:all" "ancestral 100:100" "ancestral 50:50" "ancestral 40:40" "ancestral 30:30"
         "dpm2m 20:20" "dpm2m 30:30" "ddim 50:50")
for pair in "human_walk_cmu:human_walk_cmu_131_01" "human_hop_cmu:human_hop_cmu_131_03" \
            "fox_survey_khronos:fox_survey_khronos"; do
  model=${pair%%:*}
  clip=${pair##*:}
  for config in "${configs[@]}"; do
    sampler=${config%% *}
    rest=${config#* }
    label=${rest%%:*}
    steps=${rest##*:}
    json="$out/${model}_${sampler}_${label}.json"
    [ -f "$json" ] || "$sinmdm" eval -m "onnx-models/$model.onnx" --clip "tests/data/bvh/$clip.bvh" \
      --samples 20 --steps "$steps" --sampler "$sampler" --quiet --json "$json" >/dev/null
  done
done
.venv/bin/python - "$out" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
for model in ["human_walk_cmu", "human_hop_cmu", "fox_survey_khronos"]:
    runs = sorted(out.glob(f"{model}_*.json"))
    base = json.loads((out / f"{model}_ancestral_1000.json").read_text())
    bc, bg = base["report"]["coverage"]["mean"], base["report"]["global_diversity"]["mean"]
    print(f"\n{model} (raw samples; ratios against 1 000 ancestral steps)\n")
    print("| sampler | steps | coverage | global diversity | coverage / base | diversity / base | jitter x clip | s per sample |")
    print("|---|---|---|---|---|---|---|---|")
    def key(p):
        d = json.loads(p.read_text())
        return (d["sampler"], int(d["steps"]) if d["steps"] != "all" else 1000)
    for path in sorted(runs, key=key):
        d = json.loads(path.read_text())
        c, g = d["report"]["coverage"]["mean"], d["report"]["global_diversity"]["mean"]
        jitter = d["feet"]["raw"]["jitter_ratio"]
        print(f"| {d['sampler']} | {d['steps']} | {c:.1f} | {g:.3f} | {c / bc:.3f} | {g / bg:.3f} | "
              f"{jitter:.2f} | {d['sampling_seconds'] / d['samples']:.3f} |")
PY

#!/usr/bin/env python3
"""What fewer steps per stream block cost: `sinmdm eval --stream` (3 streams of 60 s, feet
planted) on the shipped models for each sampler and step count, two seeds, as one Markdown
table of means over the seeds: coverage, global diversity, jitter against the clip's, frames
nearly still (samples / clip), speed p50 ratio, the speed and acceleration distances, and the
network's seconds per stream-second (noisy on a shared machine: compare within one run).

Run from the repository root after scripts/setup_tests.sh:
  .venv/bin/python lab/scripts/stream_steps_table.py [OUT_DIR]
"""

import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SINMDM = ROOT / "target" / "release" / "sinmdm"
MODELS = {
    "walk": ("human_walk_cmu", "human_walk_cmu_131_01.bvh"),
    "hop": ("human_hop_cmu", "human_hop_cmu_131_03.bvh"),
    "zombie": ("human_zombie_walk_fair", "human_zombie_walk_fair.bvh"),
    "fox": ("fox_survey_khronos", "fox_survey_khronos.bvh"),
}
CANDIDATES = [("ancestral", 20), ("ancestral", 10), ("ddim", 10), ("dpm2m", 10), ("dpm2m", 6), ("dpm2m", 4)]
SEEDS = [0, 3]
SAMPLES, FRAMES = 3, 1800


def scores(path):
    d = json.loads(path.read_text())
    kin = d["kinematics"]
    return {
        "coverage": d["planted_report"]["coverage"]["mean"],
        "diversity": d["planted_report"]["global_diversity"]["mean"],
        "jitter": d["feet"]["planted"]["jitter_ratio"] if "planted" in d["feet"] else d["feet"]["raw"]["jitter_ratio"],
        "still": 100 * kin["planted"]["still_share"],
        "clip_still": 100 * kin["clip"]["still_share"],
        "p50": kin["planted"]["speed_ratios"][1],
        "speed_distance": kin["planted"]["speed_distance"],
        "acceleration_distance": kin["planted"]["acceleration_distance"],
        "seconds": d["sampling_seconds"] / (SAMPLES * FRAMES / 30.0),
    }


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "out" / "stream_steps"
    out.mkdir(parents=True, exist_ok=True)
    print("| model | sampler, steps | coverage | global diversity | jitter x clip | still % (clip) "
          "| speed p50 x clip | speed distance | acceleration distance | network s per stream-s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, (model, clip) in MODELS.items():
        for sampler, steps in CANDIDATES:
            runs = []
            for seed in SEEDS:
                path = out / f"{name}_{sampler}{steps}_seed{seed}.json"
                if not path.exists():
                    subprocess.run(
                        [str(SINMDM), "eval", "-m", str(ROOT / "onnx-models" / f"{model}.onnx"),
                         "--clip", str(ROOT / "tests" / "data" / "bvh" / clip), "--stream",
                         "--samples", str(SAMPLES), "--frames", str(FRAMES), "--seed", str(seed),
                         "--steps", str(steps), "--sampler", sampler, "--json", str(path)],
                        check=True, capture_output=True,
                    )
                runs.append(scores(path))
            m = {k: sum(r[k] for r in runs) / len(runs) for k in runs[0]}
            print(f"| {name} | {sampler} {steps} | {m['coverage']:.1f} | {m['diversity']:.3f} | {m['jitter']:.2f} "
                  f"| {m['still']:.1f} ({m['clip_still']:.1f}) | {m['p50']:.2f} | {m['speed_distance']:.3f} "
                  f"| {m['acceleration_distance']:.3f} | {1000 * m['seconds']:.2f} ms |", flush=True)


if __name__ == "__main__":
    main()

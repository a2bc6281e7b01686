"""How fast the root turns about the up axis in a model's samples against its clip: the heading's
rate per frame (degrees per second) at the median, the 99th percentile and the most, and how
many sample frames turn faster than the clip ever does. A model that holds a heading and then
swings to another shows as a 99th percentile far over the clip's.

Usage (from the repository root, after `cargo build --release`):
    .venv/bin/python lab/scripts/root_turn.py CLIP.bvh MODEL.onnx [MODEL.onnx ...]
Three samples of 20 s per model, seed 0, raw feet.
"""

import json
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np
import onnx

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))
from test_kinematic_fidelity import turn_rates  # noqa: E402


def model_layout(model):
    meta = json.loads(next(e.value for e in onnx.load(str(model)).metadata_props
                           if e.key == "sinmdm.metadata"))
    up = {"+Y": [0, 1, 0], "+Z": [0, 0, 1]}[meta["layout"]["up"]]
    return np.array(up, float), meta["layout"]["fps"]


def main():
    clip, models = pathlib.Path(sys.argv[1]), sys.argv[2:]
    up, fps = model_layout(models[0])
    frame_time = float(re.search(r"Frame Time:\s*([\d.eE+-]+)", clip.read_text()).group(1))
    clip_rate = turn_rates(clip, max(1, round(1 / frame_time / fps)), fps, up)
    print("| motion | heading rate p50 / p99 / most (degrees/s) | frames turning faster than the clip's most |")
    print("|---|---|---|")
    print(f"| clip | {np.median(clip_rate):.0f} / {np.percentile(clip_rate, 99):.0f} / "
          f"{clip_rate.max():.0f} | |")
    with tempfile.TemporaryDirectory() as folder:
        for model in models:
            out = pathlib.Path(folder) / f"{pathlib.Path(model).stem}.bvh"
            subprocess.run([str(ROOT / "target/release/sinmdm"), "generate", "-m", model, "--count", "3",
                            "--seed", "0", "--seconds", "20", "--feet", "raw", "--quiet", "-o", str(out)],
                           check=True, capture_output=True)
            rate = np.concatenate([turn_rates(out.with_name(f"{out.stem}_{i:03d}.bvh"), 1, fps, up)
                                   for i in range(3)])
            print(f"| {pathlib.Path(model).name} | {np.median(rate):.0f} / {np.percentile(rate, 99):.0f} / "
                  f"{rate.max():.0f} | {np.mean(rate > clip_rate.max()) * 100:.1f} % |")


if __name__ == "__main__":
    main()

"""How fast a model's samples travel against their clip, raw and with their feet planted: the
carrying root's speed over the ground (file units per second; median and mean, and as multiples
of the clip's), which the body's kinematic figures (taken relative to the root) cannot see.

Usage (from the repository root, after `cargo build --release`):
    .venv/bin/python lab/scripts/root_travel.py MODEL.onnx CLIP.bvh [SECONDS]
Four samples of SECONDS (default 20) each way, seed 0.
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
from test_kinematic_fidelity import carrying_root, positions  # noqa: E402


def ground_speed(path, ground, fps, every=1):
    joints, _, _, _ = positions(path, every)
    root = joints[:, carrying_root(path, joints)]
    return np.linalg.norm(np.diff(root[:, ground], axis=0), axis=1) * fps


def main():
    model, clip = sys.argv[1], pathlib.Path(sys.argv[2])
    seconds = sys.argv[3] if len(sys.argv) > 3 else "20"
    meta = json.loads(next(e.value for e in onnx.load(model).metadata_props
                           if e.key == "sinmdm.metadata"))
    fps = meta["layout"]["fps"]
    ground = {"+Y": [0, 2], "+Z": [0, 1]}[meta["layout"]["up"]]
    frame_time = float(re.search(r"Frame Time:\s*([\d.eE+-]+)", clip.read_text()).group(1))
    clip_speed = ground_speed(clip, ground, fps, every=max(1, round(1 / frame_time / fps)))
    print("| motion | root ground speed, median / mean (units/s) | x the clip's |")
    print("|---|---|---|")
    print(f"| clip | {np.median(clip_speed):.2f} / {clip_speed.mean():.2f} | |")
    with tempfile.TemporaryDirectory() as folder:
        for feet in ("raw", "planted"):
            out = pathlib.Path(folder) / f"{feet}.bvh"
            subprocess.run([str(ROOT / "target/release/sinmdm"), "generate", "-m", model, "--count", "4",
                            "--seed", "0", "--seconds", seconds, "--feet", feet, "--quiet", "-o", str(out)],
                           check=True, capture_output=True)
            speed = np.concatenate([ground_speed(out.with_name(f"{feet}_{i:03d}.bvh"), ground, fps)
                                    for i in range(4)])
            print(f"| samples, {feet} | {np.median(speed):.2f} / {speed.mean():.2f} | "
                  f"{np.median(speed) / np.median(clip_speed):.2f} / {speed.mean() / clip_speed.mean():.2f} |")


if __name__ == "__main__":
    main()

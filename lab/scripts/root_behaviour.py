"""The root's own behaviour of a model's samples against its clip: ground speed and path
curvature (the turn of the direction of travel per distance travelled), as quartiles, for world-
and heading-root models alike (both are read from the decoded course, not from the rows).

Usage (from the repository root, after building):
    .venv/bin/python lab/scripts/root_behaviour.py CLIP.bvh MODEL.onnx [MODEL.onnx ...]

Each model makes 20 samples of twice the clip's length (`sinmdm eval --features-json`, seed 0)
and the clip is encoded in its layout (`sinmdm encode`). Prints one Markdown row per model and
one for the clip (in the first model's layout)."""

import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

SINMDM = "target/release/sinmdm"
SMOOTH_SECONDS = 0.5  # travel direction over about a stride, so a step's sway is not a turn


def course(layout, rows):
    """Ground positions [N, 2] (canonical X, Z) of one sample's raw features [F, N]."""
    root = layout["root"]
    if root.get("heading"):
        forward, leftward, turn = rows[0].astype(float), rows[1].astype(float), rows[2].astype(float)
        h = root["heading"]["start"] + np.concatenate([[0.0], np.cumsum(turn[1:])])
        dx = np.sin(h) * forward + np.cos(h) * leftward
        dz = np.cos(h) * forward - np.sin(h) * leftward
    else:
        axes = root["axes"]
        dx = rows[axes.index("X")].astype(float) if "X" in axes else np.zeros(rows.shape[1])
        dz = rows[axes.index("Z")].astype(float) if "Z" in axes else np.zeros(rows.shape[1])
    dx[0] = dz[0] = 0.0
    return np.stack([np.cumsum(dx), np.cumsum(dz)], axis=1)


def behaviour(layout, samples):
    """Speeds (heights/s) and curvatures (radians per height) of every moving frame."""
    fps, height = layout["fps"], layout["skeleton_height"]
    lag = max(int(round(SMOOTH_SECONDS * fps)), 1)
    speeds, curvatures = [], []
    for rows in samples:
        p = course(layout, rows)
        step = p[lag:] - p[:-lag]
        distance = np.hypot(step[:, 0], step[:, 1])
        speed = distance / height * fps / lag
        direction = np.unwrap(np.arctan2(step[:, 0], step[:, 1]))
        moving = speed[1:] >= 0.2
        turn = np.abs(np.diff(direction))[moving]
        travelled = (distance[1:] / height / lag)[moving]
        speeds.extend(speed[speed >= 0.2])
        curvatures.extend(turn / np.maximum(travelled, 1e-9))
    return np.asarray(speeds), np.asarray(curvatures)


def quartiles(values):
    if len(values) == 0:
        return "-"
    q = np.percentile(values, [25, 50, 75])
    return f"{q[0]:.2f} / {q[1]:.2f} / {q[2]:.2f}"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    clip = sys.argv[1]
    print("| model | root layout | moving share | speed quartiles (heights/s) | curvature quartiles (rad/height) |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        first_layout, clip_rows = None, None
        for i, model in enumerate(sys.argv[2:]):
            out = work / f"{i}.json"
            subprocess.run([SINMDM, "eval", "-m", model, "--clip", clip, "--samples", "20", "--quiet",
                            "--features-json", str(out)], check=True, capture_output=True)
            encoded = work / f"{i}.clip.json"
            subprocess.run([SINMDM, "encode", clip, "-m", model, "-o", str(encoded)], check=True,
                           capture_output=True)
            import onnx
            meta = json.loads({p.key: p.value for p in onnx.load(model).metadata_props}["sinmdm.metadata"])
            layout = meta["layout"]
            samples = np.asarray(json.load(open(out))["samples"], dtype=np.float32)
            speeds, curves = behaviour(layout, samples)
            frames = samples.shape[0] * samples.shape[2]
            kind = "heading" if layout["root"].get("heading") else "world"
            print(f"| {Path(model).name} | {kind} | {len(speeds) / frames:.2f} | {quartiles(speeds)} | "
                  f"{quartiles(curves)} |")
            if first_layout is None:
                first_layout = layout
                clip_rows = np.asarray(json.load(open(encoded))["samples"], dtype=np.float32)
        speeds, curves = behaviour(first_layout, clip_rows)
        frames = clip_rows.shape[0] * clip_rows.shape[2]
        print(f"| the clip | | {len(speeds) / frames:.2f} | {quartiles(speeds)} | {quartiles(curves)} |")


if __name__ == "__main__":
    main()

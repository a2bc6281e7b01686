"""Which joints move too fast or too slowly: each joint's speed relative to the joint that carries
the body (in that joint's frame, skeleton heights per second, at the model's frame rate), median
and 90th percentile, in four samples of 20 s (seed 0, default sampling and feet) against the clip.
The body's speed that `sinmdm eval` pools is the mean of these per frame.

Usage: .venv/bin/python lab/scripts/joint_speeds.py CLIP.bvh MODEL.onnx
"""

import json
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
import onnx

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))
from test_kinematic_fidelity import carrying_root, positions, read_bvh, root_rotation  # noqa: E402

SINMDM = ROOT / "target" / "release" / "sinmdm"


def relative_speeds(path, height, fps, every=1):
    """Per frame pair and joint below the carrying root, its speed relative to that root."""
    joints, _, _, _ = positions(path, every)
    root = carrying_root(path, joints)
    r = root_rotation(path, root, every)
    rel = np.einsum("fji,fkj->fki", r, joints[:, root + 1:] - joints[:, root:root + 1]) / height
    return root, np.linalg.norm(np.diff(rel, axis=0), axis=2) * fps


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    clip, model = pathlib.Path(sys.argv[1]), sys.argv[2]
    meta = json.loads(next(e.value for e in onnx.load(model).metadata_props if e.key == "sinmdm.metadata"))
    height, fps = meta["layout"]["skeleton_height"], meta["layout"]["fps"]
    frame_time = next(float(line.split()[-1]) for line in clip.read_text().splitlines()
                      if line.strip().startswith("Frame Time"))
    root, clip_speeds = relative_speeds(clip, height, fps, max(1, round(1 / frame_time / fps)))
    with tempfile.TemporaryDirectory() as folder:
        out = pathlib.Path(folder) / "sample.bvh"
        subprocess.run([str(SINMDM), "generate", "-m", model, "--count", "4", "--seed", "0", "--seconds", "20",
                        "--quiet", "-o", str(out)], check=True, capture_output=True)
        sample_speeds = np.concatenate([relative_speeds(p, height, fps)[1]
                                        for p in sorted(pathlib.Path(folder).glob("sample_*.bvh"))])
    names = [j["name"] for j in read_bvh(clip)[0]]
    print("| joint | clip p50 | samples p50 | x clip | clip p90 | samples p90 | x clip |")
    print("|---|---|---|---|---|---|---|")
    for k in range(clip_speeds.shape[1]):
        c50, s50 = np.median(clip_speeds[:, k]), np.median(sample_speeds[:, k])
        c90, s90 = np.percentile(clip_speeds[:, k], 90), np.percentile(sample_speeds[:, k], 90)
        ratio = lambda s, c: f"{s / c:.2f}" if c > 1e-6 else "-"  # noqa: E731
        print(f"| {names[root + 1 + k]} | {c50:.3f} | {s50:.3f} | {ratio(s50, c50)} | {c90:.3f} | {s90:.3f} | "
              f"{ratio(s90, c90)} |")


if __name__ == "__main__":
    main()

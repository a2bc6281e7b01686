"""Draws how samples move against their clip: the body's mean joint speed per frame (the measure
`sinmdm eval` pools, SPEC section 9's kinematic fidelity), the clip's in black above, then one
panel per model with three of its samples, as a PNG a person can look at.

Usage: .venv/bin/python lab/scripts/speed_plot.py CLIP.bvh OUT.png MODEL.onnx [MODEL.onnx ...]

Frozen samples lie flat at the bottom, damped ones below the clip's band, shaking ones as a
dense saw above it. The figure is drawn with numpy and written with zlib (no plotting library).
"""

import pathlib
import subprocess
import sys
import tempfile
import zlib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))
from test_kinematic_fidelity import body_kinematics  # noqa: E402

SINMDM = ROOT / "target" / "release" / "sinmdm"
WIDTH, PANEL, MARGIN = 900, 140, 8
COLOURS = [(0, 0, 0), (200, 40, 40), (40, 120, 200), (40, 160, 60)]


def model_layout(model):
    import json
    import onnx
    meta = json.loads(next(e.value for e in onnx.load(str(model)).metadata_props if e.key == "sinmdm.metadata"))
    return meta["layout"]["skeleton_height"], meta["layout"]["fps"]


def samples(model, frames, folder):
    out = folder / f"{pathlib.Path(model).stem}.bvh"
    subprocess.run([str(SINMDM), "generate", "-m", str(model), "--count", "3", "--seed", "0", "--frames",
                    str(frames), "--quiet", "-o", str(out)], check=True, capture_output=True)
    return [folder / f"{out.stem}_{i:03d}.bvh" for i in range(3)]


def draw(panels, top):
    height = len(panels) * (PANEL + MARGIN) + MARGIN
    image = np.full((height, WIDTH, 3), 255, np.uint8)
    for p, curves in enumerate(panels):
        y0 = MARGIN + p * (PANEL + MARGIN)
        image[y0 + PANEL, :] = 200
        for colour, speeds in curves:
            xs = np.linspace(0, WIDTH - 1, len(speeds)).astype(int)
            ys = y0 + PANEL - 1 - np.clip(speeds / top * (PANEL - 1), 0, PANEL - 1).astype(int)
            for (xa, ya), (xb, yb) in zip(zip(xs, ys), zip(xs[1:], ys[1:])):
                for t in np.linspace(0, 1, max(abs(yb - ya), xb - xa, 1) + 1):
                    image[int(round(ya + (yb - ya) * t)), int(round(xa + (xb - xa) * t))] = colour
    return image


def write_png(path, image):
    raw = b"".join(b"\x00" + row.tobytes() for row in image)
    def chunk(kind, data):
        body = kind + data
        return len(data).to_bytes(4, "big") + body + zlib.crc32(body).to_bytes(4, "big")
    h, w, _ = image.shape
    header = w.to_bytes(4, "big") + h.to_bytes(4, "big") + bytes([8, 2, 0, 0, 0])
    pathlib.Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                                   + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    clip, out, models = pathlib.Path(sys.argv[1]), sys.argv[2], sys.argv[3:]
    height, fps = model_layout(models[0])
    clip_fps = _clip_fps(clip)
    # A clip at a multiple of the model's rate is read at the model's; any other at its own
    # (speeds are in H per second either way).
    every = round(clip_fps / fps)
    if every >= 1 and abs(clip_fps / fps - every) < 1e-3:
        clip_speeds = body_kinematics(clip, height, fps, every=every)[0]
        seconds = len(clip_speeds) / fps
    else:
        clip_speeds = body_kinematics(clip, height, clip_fps)[0]
        seconds = len(clip_speeds) / clip_fps
    frames = int(round(2 * seconds * fps)) + 1
    panels = [[(COLOURS[0], np.concatenate([clip_speeds, clip_speeds]))]]
    with tempfile.TemporaryDirectory() as folder:
        for model in models:
            curves = [(COLOURS[0], np.concatenate([clip_speeds, clip_speeds]))]
            for i, path in enumerate(samples(model, frames, pathlib.Path(folder))):
                curves.append((COLOURS[1 + i], body_kinematics(path, height, fps)[0]))
            panels.append(curves)
    top = 3.0 * np.percentile(clip_speeds, 90)
    write_png(out, draw(panels, top))
    print(f"wrote {out}: clip on top, then {', '.join(pathlib.Path(m).name for m in models)}; "
          f"speed axis 0-{top:.3f} H/s")


def _clip_fps(path):
    for line in pathlib.Path(path).read_text().splitlines():
        if line.startswith("Frame Time:"):
            return 1.0 / float(line.split(":")[1])
    raise ValueError(f"{path}: no Frame Time")


if __name__ == "__main__":
    main()

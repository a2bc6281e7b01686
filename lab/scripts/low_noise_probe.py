"""How well a model's denoiser gives back its own clip from the clip noised at a chosen step: the
clip's features (as `sinmdm encode` writes them) normalised as the model does, noised at step t
with four noise draws, denoised once; printed per t: the prediction's RMS error (normalised
feature units) and its per-frame change over the clip's (the median over frames of the RMS over
features of the frame-to-frame difference). A denoiser that smooths its input shows a ratio
under 1 at low t; one that cannot give back its input at all (an under-trained network that
predicts roughly its mean pose) an error near 0.5 at every t.

Usage: .venv/bin/python lab/scripts/low_noise_probe.py MODEL.onnx FEATURES.json
"""
import json
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
from sinmdm_reference.model import Model  # noqa: E402
from sinmdm_reference.schedule import Schedule  # noqa: E402

STEPS = [1, 5, 20, 50, 100, 200, 400, 700, 999]


def frame_change(x):
    return np.median(np.sqrt((np.diff(x, axis=-1) ** 2).mean(axis=-2)))


def main(model_path, features_path):
    model = Model(model_path)
    raw = np.asarray(json.loads(pathlib.Path(features_path).read_text())["samples"][0], dtype=np.float32)
    x0 = model.normalize(raw)[None]
    abar = Schedule.cosine(model.metadata["diffusion"]["steps"]).alphas_cumprod
    rng = np.random.default_rng(0)
    clip = frame_change(x0)
    print(f"{model_path}: the clip's frame change {clip:.3f}")
    print("| t | abar | error (RMS) | frame change x clip |")
    print("|---|---|---|---|")
    for t in STEPS:
        errors, ratios = [], []
        for _ in range(4):
            eps = rng.standard_normal(x0.shape).astype(np.float32)
            x_t = (np.sqrt(abar[t]) * x0 + np.sqrt(1 - abar[t]) * eps).astype(np.float32)
            x0_hat = model.denoise(x_t, np.array([t]))
            errors.append(np.sqrt(((x0_hat - x0) ** 2).mean()))
            ratios.append(frame_change(x0_hat) / clip)
        print(f"| {t} | {abar[t]:.4f} | {np.mean(errors):.3f} | {np.mean(ratios):.3f} |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

"""How much of a clip's motion, as the network sees it, lives in features that barely vary.

Each feature is standardised by its spread over frames, floored at a share of the mean spread
(runtime/src/motion/normalize.rs). A feature whose spread is far under the mean (rounding noise on
a joint that stays still) is then scaled up to the size of the motion. This prints, for each
floor share, how many features lie under 5 % of the mean spread and their share of the
standardised variance and of the frame-to-frame change, then those features one by one with
their lag-1 autocorrelation (near 1: smooth motion; well under 1: noise).

Usage (from the repository root, after `cargo build --release`):
    .venv/bin/python lab/scripts/feature_noise.py MODEL.onnx CLIP.bvh
"""

import json
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, "python")
from sinmdm_reference.features import read_features  # noqa: E402

SMALL = 0.05


def clip_features(model, clip):
    with tempfile.TemporaryDirectory() as folder:
        out = f"{folder}/features.json"
        subprocess.run(["target/release/sinmdm", "encode", "-m", model, clip, "-o", out],
                       check=True, capture_output=True)
        arrays = [a for a in read_features(out) if hasattr(a, "shape")]
    return np.asarray(arrays[0], dtype=np.float64).squeeze().T  # [frames, features]


def main():
    model, clip = sys.argv[1], sys.argv[2]
    x = clip_features(model, clip)
    spread = x.std(axis=0)
    ratio = spread / spread.mean()
    print(f"{clip}: {x.shape[0]} frames, {x.shape[1]} features")
    print("| floor share | features under 5 % of the mean spread, still varying | their share of the variance | of the frame-to-frame change |")
    print("|---|---|---|---|")
    for share in (1e-3, 0.01, 0.02, 0.05):
        z = (x - x.mean(axis=0)) / np.maximum(spread, share * spread.mean())
        variance = z.var(axis=0)
        change = (np.diff(z, axis=0) ** 2).mean(axis=0)
        small = (ratio < SMALL) & (z.std(axis=0) > 0.01)
        print(f"| {share:g} | {small.sum()} | {variance[small].sum() / variance.sum():.3f} "
              f"| {change[small].sum() / change.sum():.3f} |")
    z = (x - x.mean(axis=0)) / np.maximum(spread, 1e-3 * spread.mean())
    for i in np.where((ratio < SMALL) & (z.std(axis=0) > 0.5))[0]:
        lag1 = np.corrcoef(z[1:, i], z[:-1, i])[0, 1]
        print(f"feature {i}: spread {ratio[i]:.4f} of the mean, lag-1 autocorrelation {lag1:.2f}")


if __name__ == "__main__":
    main()

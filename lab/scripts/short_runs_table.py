"""Prints the short runs (the default with 1 000 or 3 000 steps, each its own warm-up and cosine
schedule; out/short_runs/NAME.STEPS.json from `sinmdm eval`, 20 samples, seed 0) beside the
same clips' 17 000-step default from the checkpoint sweep (out/checkpoint_sweep/NAME.17000.json).

Usage: python3 lab/scripts/short_runs_table.py [SHORT_DIR] [SWEEP_DIR]"""

import json
import pathlib
import re
import sys

short = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/short_runs")
sweep = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "out/checkpoint_sweep")


def row(path):
    d = json.loads(path.read_text())
    r = d["report"]
    return (r["coverage"]["mean"], r["global_diversity"]["mean"], r["clip_intra_diversity"],
            d["replay"]["mean_seconds"], d["feet"]["raw"]["jitter_ratio"])


print("| clip | steps | coverage | global diversity | clip intra | replay s | jitter x clip |")
print("|---|---|---|---|---|---|---|")
names = sorted({re.match(r"(.+)\.\d+\.json$", p.name).group(1) for p in short.glob("*.json")})
for name in names:
    runs = [(int(p.name.split(".")[-2]), p) for p in short.glob(f"{name}.*.json")]
    full = sweep / f"{name}.17000.json"
    if full.exists():
        runs.append((17000, full))
    for steps, path in sorted(runs):
        c, g, i, rp, j = row(path)
        print(f"| {name} | {steps} | {c:.1f} | {g:.3f} | {i:.3f} | {rp:.2f} | {j:.2f} |")

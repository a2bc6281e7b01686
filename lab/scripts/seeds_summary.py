"""Mean and standard error over eval seeds 0-4 of one model's coverage and global diversity:
BASE.json (seed 0) and BASE.seedN.json (seeds 1-4), as `sinmdm eval --seed N --json` writes.

Usage: python3 lab/scripts/seeds_summary.py BASE [BASE ...]   (BASE without .json)"""

import json
import statistics
import sys

for base in sys.argv[1:]:
    paths = [f"{base}.json"] + [f"{base}.seed{s}.json" for s in range(1, 5)]
    reports = [json.load(open(p))["report"] for p in paths]
    line = [base]
    for key in ("coverage", "global_diversity"):
        values = [r[key]["mean"] for r in reports]
        se = statistics.stdev(values) / len(values) ** 0.5
        line.append(f"{key} {statistics.mean(values):.3f} ± {se:.3f}")
    print(", ".join(line))

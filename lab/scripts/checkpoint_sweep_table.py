"""Prints what lab/scripts/checkpoint_sweep.sh measured: per clip, its facts (frames, motion
span, root) and, per kept checkpoint, coverage, global diversity, replay and jitter against the
clip's, with the issue's goals marked.

Usage: python3 lab/scripts/checkpoint_sweep_table.py [OUT_DIR]"""

import json
import pathlib
import re
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/checkpoint_sweep")


def facts(name):
    text = (out / f"{name}.facts").read_text() if (out / f"{name}.facts").exists() else ""
    frames = re.search(r"\((\d+) frames at ([\d.]+) fps\)", text)
    span = re.search(r"motion span\s+([\d.]+) s", text)
    root = re.search(r"^root\s+(\w+)", text, re.M)
    return (int(frames.group(1)) if frames else None, float(frames.group(2)) if frames else None,
            float(span.group(1)) if span else None, root.group(1) if root else "?")


def scores(path):
    d = json.loads(path.read_text())
    r = d["report"]
    return {
        "coverage": r["coverage"]["mean"],
        "diversity": r["global_diversity"]["mean"],
        "clip_intra": r["clip_intra_diversity"],
        "replay": d["replay"]["mean_seconds"],
        "jitter": d["feet"]["raw"]["jitter_ratio"],
    }


def meets(s):
    """The issue's goals: coverage >= 95; diversity >= 1.2 for a varied clip (its own intra
    diversity >= 0.7), else no replay (<= 1 s); jitter <= 1.5x the clip's."""
    varied = s["clip_intra"] >= 0.7
    second = s["diversity"] >= 1.2 if varied else s["replay"] <= 1.0
    return s["coverage"] >= 95 and second and s["jitter"] <= 1.5


def table():
    rows = {}
    for path in sorted(out.glob("*.json")):
        m = re.match(r"(.+)\.(\d+)\.json$", path.name)
        if not m:
            continue
        rows.setdefault(m.group(1), {})[int(m.group(2))] = scores(path)
    return rows


if __name__ == "__main__":
    rows = table()
    print("| clip | frames (fps) | motion span | root | train s | step | coverage | global diversity | clip intra | replay s | jitter x clip | goals |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, by_step in rows.items():
        frames, fps, span, root = facts(name)
        trained = (out / f"{name}.trained").read_text().strip() if (out / f"{name}.trained").exists() else "-"
        for step, s in sorted(by_step.items()):
            print(f"| {name} | {frames} ({fps:g}) | {span} | {root} | {trained} | {step} | "
                  f"{s['coverage']:.1f} | {s['diversity']:.3f} | {s['clip_intra']:.3f} | "
                  f"{s['replay']:.2f} | {s['jitter']:.2f} | {'met' if meets(s) else '-'} |")

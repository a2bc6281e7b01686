"""The dance task's measurement: beat-hit rate, Beat Align Score (each beside its random-phase
control), jitter and coverage of dances at tempo ratios 0.8, 1.0 and 1.25, setting by setting,
against free samples of the same model (`sinmdm eval`, planted feet, default sampling).

    .venv/bin/python lab/scripts/dance_table.py MODEL.onnx CLIP.bvh [--samples 8] [--seconds 12]

The music is a metronome at twice the tempo that puts every other beat at the ratio asked
(the level the task chooses by itself), so each ratio is exact in frames. Prints one Markdown
table; a row passes when hit >= 0.70, BAS >= 0.50 and >= its control + 0.20, jitter <= the larger
of 1.5x the free samples' and the clip's / ratio^2, and coverage >= 0.9x the free samples'.
"""

import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
SINMDM = ROOT / "target" / "release" / "sinmdm"

SETTINGS = [
    ("naive: hold 2, hard borders", ["--hold", 2, "--ramp", 1, "--order", "reference"]),
    ("hold 12, ramp 13, shuffled (default)", []),
    ("hold 12, ramp 13, reference order", ["--order", "reference"]),
    ("hold 12, ramp 13, root free", ["--root", "free"]),
    ("hold 9, ramp 10", ["--hold", 9, "--ramp", 10]),
    ("hold 7, ramp 8", ["--hold", 7, "--ramp", 8]),
    ("hold 5, ramp 3", ["--hold", 5, "--ramp", 3]),
    ("hold 5, ramp 3, reference order", ["--hold", 5, "--ramp", 3, "--order", "reference"]),
    ("hold 3, ramp 3", ["--hold", 3, "--ramp", 3]),
    ("hold 5, ramp 1", ["--hold", 5, "--ramp", 1]),
]
RATIOS = [0.8, 1.0, 1.25]


def evaluate(model, clip, samples, frames, seed, extra, work, name):
    out = work / f"{name}.json"
    args = [SINMDM, "eval", "-m", model, "--clip", clip, "--samples", samples, "--frames", frames,
            "--seed", seed, "--quiet", "--json", out, *extra]
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if done.returncode != 0:
        return None, done.stderr.strip().splitlines()[-1]
    doc = json.loads(out.read_text())
    return doc, None


def main():
    p = argparse.ArgumentParser()
    p.add_argument("model")
    p.add_argument("clip")
    p.add_argument("--samples", type=int, default=8)
    p.add_argument("--seconds", type=float, default=12.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--setting", action="append", default=[], metavar="LABEL=ARGS",
                   help="measure this setting instead of the built-in list (repeatable), "
                        "e.g. 'hold 5=--hold 5 --ramp 2'")
    a = p.parse_args()
    settings = [(label, args.split()) for label, args in (x.split("=", 1) for x in a.setting)]
    settings = settings or SETTINGS
    work = pathlib.Path(tempfile.mkdtemp(prefix="dance_table_"))
    fps = 30.0
    frames = int(round(a.seconds * fps))
    free, err = evaluate(a.model, a.clip, a.samples, frames, a.seed, [], work, "free")
    if free is None:
        sys.exit(f"free samples: {err}")
    fps = free["planted_report"]["sample_frames"] and 30.0
    free_cov = free["planted_report"]["coverage"]["mean"]
    free_jit = free["feet"]["planted"]["mean"]["jitter"]
    clip_jit = free["feet"]["clip"]["jitter"]
    # The reference's beat interval, from a first dance's record.
    probe = work / "probe.json"
    done = subprocess.run([str(x) for x in [SINMDM, "eval", "-m", a.model, "--clip", a.clip, "--samples", 1,
                                            "--frames", frames, "--bpm", 120, "--quiet", "--steps", 2,
                                            "--beats-out", probe]], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(done.stderr)
    ref = json.loads(probe.read_text())["reference_beats"]
    gaps = sorted(b - a_ for a_, b in zip(ref, ref[1:]))
    ref_interval = gaps[len(gaps) // 2]
    print(f"free samples: coverage {free_cov:.1f}, global diversity "
          f"{free['planted_report']['global_diversity']['mean']:.3f}, jitter {free_jit:.2f} "
          f"(clip {clip_jit:.2f}); reference beat every {ref_interval} frames "
          f"({60 * fps / ref_interval:.1f} BPM), {a.samples} samples x {a.seconds:g} s, seed {a.seed}")
    print()
    print("| setting | ratio | hit (control) | BAS (control) | jitter / free | coverage / free | global div | passes |")
    print("|---|---|---|---|---|---|---|---|")
    for label, extra in settings:
        for ratio in RATIOS:
            interval = min(max(round(ratio * ref_interval), -(-3 * ref_interval // 4)),
                           (5 * ref_interval) // 4)
            bpm = 2 * 60.0 * fps / interval
            doc, err = evaluate(a.model, a.clip, a.samples, frames, a.seed,
                                ["--bpm", repr(bpm), *extra], work, f"{label}-{ratio}")
            if doc is None:
                print(f"| {label} | {ratio} | refused: {err} | | | | | |")
                continue
            b = doc["beats"]
            cov = doc["planted_report"]["coverage"]["mean"]
            jit = doc["feet"]["planted"]["mean"]["jitter"]
            true_ratio = interval / ref_interval
            jit_limit = max(1.5 * free_jit, clip_jit / true_ratio ** 2)
            ok = (b["hit_rate"] >= 0.70 and b["bas"] >= 0.50 and b["bas"] >= b["bas_control"] + 0.20
                  and jit <= jit_limit and cov >= 0.9 * free_cov)
            print(f"| {label} | {true_ratio:.2f} | {b['hit_rate']:.2f} ({b['hit_rate_control']:.2f}) | "
                  f"{b['bas']:.3f} ({b['bas_control']:.3f}) | {jit / free_jit:.2f} (limit "
                  f"{jit_limit / free_jit:.2f}) | {cov / free_cov:.3f} | "
                  f"{doc['planted_report']['global_diversity']['mean']:.3f} | {'yes' if ok else 'no'} |",
                  flush=True)


if __name__ == "__main__":
    main()

"""Prints a shipped heading-relative model's steering table (the "Steering" section of its card):
`sinmdm eval` with each course, 8 samples of 20 s (the figure eight 120 s), default sampling,
seed 0. The velocity schedule changes speed and turn every 2 s (lab/scripts/velocity_schedule.csv,
speeds as multiples of the clip's mean forward speed) and is run as streams.

Usage (from the repository root, after `cargo build --release`):
    python3 lab/scripts/steer_table.py MODEL.onnx CLIP.bvh
"""

import pathlib
import re
import subprocess
import sys
import tempfile


def clip_speed(model: str) -> float:
    """The clip's mean forward speed, file units per second (what --circle walks at)."""
    sys.path.insert(0, "python")
    from sinmdm_reference.model import Model
    from sinmdm_reference.steer import limits

    lo, hi, _ = limits(Model(model))
    return (lo + hi) / 2.0


def evaluate(model: str, clip: str, extra: list[str]) -> str:
    return subprocess.run(
        ["target/release/sinmdm", "eval", "-m", model, "--clip", clip, "--samples", "8",
         "--quiet", *extra],
        check=True, capture_output=True, text=True,
    ).stdout


def span(values: list[float], digits: int) -> str:
    return f"{min(values):.{digits}f}-{max(values):.{digits}f}"


def row(name: str, text: str) -> str:
    mean = [float(m) for m in re.findall(r"path distance mean ([\d.]+)", text)]
    worst = [float(m) for m in re.findall(r"path distance mean [\d.]+ max ([\d.]+)", text)]
    facing = [float(m) for m in re.findall(r"facing against travel median ([\d.]+) degrees", text)]
    over = [float(m) for m in re.findall(r"degrees, (\d+) % over 45", text)]
    planted = text.split("samples with their feet planted")[1]
    coverage = re.search(r"coverage \(%\) ↑ \| ([\d.]+)", planted).group(1)
    jitter = re.search(r"jitter, samples / clip \| \| ([\d.]+) \| ([\d.]+)", text)
    skating = re.search(r"skating ratio \(%\) ↓ \| [\d.]+ \| [\d.]+ \| ([\d.]+)", text).group(1)
    path = f"{span(mean, 3)} / {span(worst, 3)}" if mean else ""
    face = f"{span(facing, 1)} degrees / {span(over, 0)} %" if facing else ""
    return f"| {name} | {path} | {face} | {coverage} | {jitter.group(2)} | {skating} % |"


def main() -> None:
    model, clip = sys.argv[1], sys.argv[2]
    speed = clip_speed(model)
    schedule = pathlib.Path("lab/scripts/velocity_schedule.csv").read_text().split()
    with tempfile.TemporaryDirectory() as scratch:
        # The schedule's speeds, given as multiples of the clip's, in file units per second.
        velocity = pathlib.Path(scratch) / "velocity.csv"
        lines = []
        for line in schedule:
            t, factor, turn = line.split(",")
            lines.append(f"{t},{float(factor) * speed:.4f},{turn}\n")
        velocity.write_text("".join(lines))
        courses = [
            ("free (no course)", ["--frames", "600"]),
            ("`--circle 3`", ["--frames", "600", "--circle", "3"]),
            ("`--figure8 3`, 120 s (`--frames 3600`)", ["--frames", "3600", "--figure8", "3"]),
            ("`--velocity` (lab/scripts/velocity_schedule.csv), `--stream`",
             ["--frames", "600", "--velocity", str(velocity), "--stream"]),
        ]
        print("| course | root to path, mean / worst (heights) | facing against travel, median / "
              "share over 45 degrees | coverage | jitter x clip (planted) | skating (planted) |")
        print("|---|---|---|---|---|---|")
        texts = []
        for name, extra in courses:
            texts.append(evaluate(model, clip, extra))
            print(row(name, texts[-1]), flush=True)
        # How closely the velocity schedule was followed, over the samples' 2-second windows.
        speed_off = [int(m) for m in re.findall(r"speed off by at most (\d+) %", texts[-1])]
        turn_off = [int(m) for m in re.findall(r"turn by at most (\d+) %", texts[-1])]
        if speed_off and turn_off:
            print(f"\nvelocity schedule, worst 2-second window per sample: speed off by "
                  f"{min(speed_off)}-{max(speed_off)} %, turn by {min(turn_off)}-{max(turn_off)} %")


if __name__ == "__main__":
    main()

"""What the replay measure gives motion that is not a copy of the clip.

`sinmdm eval`'s replay is the longest run of sample frames that match consecutive clip frames,
each pair within 0.05 root-mean-square per 6D rotation component. On a clip that moves slowly
that tolerance spans many frames, and motion that is plainly not the clip played back (the clip
backwards, the clip faster or slower) can still score more than the 1 s the calm clips' goal
allows. This script scores such motion, built from the clip itself, on the same measure:

- hold: the longest the clip keeps one pose (what a sample standing still as long scores);
- backwards: the clip played in reverse (high wherever a stretch of the clip looks alike both
  ways: a hold, a slow passage, a move and its return);
- at 0.5x ... 3x: the clip re-timed at that speed (linear interpolation between frames); a
  speed s multiplies smooth motion's accelerations, and so about its jitter, by s squared
  (derived, not measured here), and makes the motion 1/s times the clip's length, which caps
  its run (the samples are twice the clip's length);
- samples (where given): the mean over a model's samples, as `sinmdm eval` reports it.

Inputs are features JSON files: a clip's from `sinmdm encode CLIP -m MODEL -o CLIP.json` (any
model trained on that skeleton gives the layout; lab/scripts/replay_floor.sh makes them), and a
model's samples from `sinmdm eval ... --features-json SAMPLES.json`.

Usage: .venv/bin/python lab/scripts/replay_floor.py [--tolerance T] NAME=CLIP.json[,SAMPLES.json]...
Prints a markdown table, one row per clip, in seconds."""

import argparse
import json

import numpy as np

SPEEDS = (0.5, 0.8, 1.2, 1.5, 2.0, 2.5, 3.0)


def rotations(path):
    """The file's motions as frames x 6D rotation components (f32 widened), and its frame rate."""
    data = json.loads(open(path).read())
    keep = [i for i, name in enumerate(data["columns"]) if ".rot6d[" in name]
    motions = [np.asarray(m, dtype=np.float32).astype(np.float64)[keep].T for m in data["samples"]]
    return motions, float(data["fps"])


def close_pairs(motion, clip, tolerance, chunk=128):
    """Row by row, which clip frames each motion frame lies within `tolerance` root-mean-square
    per column of (a chunk of motion frames at a time, so a long clip's differences fit in
    memory)."""
    for start in range(0, len(motion), chunk):
        part = motion[start:start + chunk]
        yield from np.sqrt(((part[:, None, :] - clip[None, :, :]) ** 2).mean(axis=2)) <= tolerance


def longest_copy(motion, clip, tolerance):
    """Frames in the longest run motion[s..s+L] matching clip[k..k+L] pair by pair: one pass over
    the motion's frames, carrying each clip frame's current run along the diagonal."""
    run = np.zeros(len(clip), dtype=int)
    best = 0
    for row in close_pairs(motion, clip, tolerance):
        run = np.where(row, np.concatenate(([0], run[:-1])) + 1, 0)
        best = max(best, int(run.max()))
    return best


def longest_hold(clip, tolerance):
    """Frames in the longest run of consecutive clip frames all within tolerance of one clip frame."""
    best = 0
    for pose in clip:
        near = np.sqrt(((clip - pose) ** 2).mean(axis=1)) <= tolerance
        run = 0
        for inside in near:
            run = run + 1 if inside else 0
            best = max(best, run)
    return best


def retimed(clip, speed):
    """The clip played at `speed` times its pace: frames at t = 0, speed, 2 speed, ... by linear
    interpolation between the clip's frames."""
    t = np.arange(0.0, len(clip) - 1 + 1e-9, speed)
    lower = np.floor(t).astype(int)
    upper = np.minimum(lower + 1, len(clip) - 1)
    frac = (t - lower)[:, None]
    return clip[lower] * (1 - frac) + clip[upper] * frac


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("clips", nargs="+", metavar="NAME=CLIP.json[,SAMPLES.json]")
    parser.add_argument("--tolerance", type=float, default=0.05)
    args = parser.parse_args()
    tol = args.tolerance
    heads = ["clip", "length s", "hold", "backwards"] + [f"at {s:g}x" for s in SPEEDS] + ["samples"]
    print("| " + " | ".join(heads) + " |")
    print("|" + "---|" * len(heads))
    for item in args.clips:
        name, files = item.split("=", 1)
        clip_path, _, samples_path = files.partition(",")
        (clip,), fps = rotations(clip_path)
        cells = [name, f"{len(clip) / fps:.1f}", f"{longest_hold(clip, tol) / fps:.2f}",
                 f"{longest_copy(clip[::-1], clip, tol) / fps:.2f}"]
        cells += [f"{longest_copy(retimed(clip, s), clip, tol) / fps:.2f}" for s in SPEEDS]
        if samples_path:
            samples, sample_fps = rotations(samples_path)
            assert sample_fps == fps, f"{samples_path}: {sample_fps} fps, the clip {fps}"
            cells.append(f"{np.mean([longest_copy(m, clip, tol) for m in samples]) / fps:.2f}")
        else:
            cells.append("-")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

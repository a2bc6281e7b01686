"""`sinmdm eval` against the benchmark's definitions written directly in numpy.

The metrics here are computed the slow, literal way: the full table of segment costs for every
start, end and clip offset, then the dynamic programme over it (what the published evaluation
kernel does), and every window pair for the intra diversity. The runtime streams them instead.
"""

import json
import subprocess

import numpy as np

from conftest import ROOT, SINMDM

MODEL = ROOT / "tests" / "data" / "models" / "walk_tiny.onnx"
WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"


def metric_features(path):
    """Frames x (every 6D rotation component and contact label) of each motion in the file."""
    data = json.loads(path.read_text())
    keep = [i for i, name in enumerate(data["columns"]) if ".rot6d[" in name or name.endswith(".contact")]
    # The file holds f32 values (shortest form): read them as f32, then widen, as the runtime does.
    return [np.asarray(sample, dtype=np.float32).astype(np.float64)[keep].T for sample in data["samples"]]


def distances(a, b):
    return np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2))


def best_segment_costs(d):
    """cost[l][n]: least sum of frame distances matching a[l:l+n] to some b[k:k+n]."""
    la, lb = d.shape
    cost = np.full((la + 1, la + 1), np.inf)
    for l in range(la):
        running = np.zeros(lb)
        for n in range(1, min(la - l, lb) + 1):
            running = running[: lb - n + 1] + d[l + n - 1, n - 1 :]
            cost[l, n] = running.min()
    return cost


def patched_nn(sample, clip, tmin=30):
    d = distances(sample, clip)
    cost = best_segment_costs(d)
    la = len(sample)
    g = np.full(la + 1, np.inf)
    g[0] = 0.0
    for j in range(tmin, la + 1):
        for l in range(0, j - tmin + 1):
            g[j] = min(g[j], g[l] + cost[l, j - l])
    return g[la] / la


def nearest_windows(a, b, n):
    """Per window of a, the mean frame distance to its best window of b."""
    d = distances(a, b)
    out = []
    for s in range(len(a) - n + 1):
        sums = [d[s + np.arange(n), k + np.arange(n)].sum() for k in range(len(b) - n + 1)]
        out.append(min(sums) / n)
    return np.array(out)


def intra(m, n=15):
    starts = range(len(m) - n + 1)
    return np.mean([np.linalg.norm(m[p : p + n] - m[q : q + n]) / n for p in starts for q in starts])


def test_eval_scores_match_the_literal_definitions(tmp_path):
    clip_json, samples_json, scores_json = tmp_path / "clip.json", tmp_path / "samples.json", tmp_path / "scores.json"
    run = lambda *a: subprocess.run([str(SINMDM), *map(str, a)], capture_output=True, text=True)  # noqa: E731
    done = run("encode", WALK, "-m", MODEL, "-o", clip_json)
    assert done.returncode == 0, done.stderr
    done = run("eval", "-m", MODEL, "--clip", WALK, "--samples", 3, "--frames", 80, "--steps", 5, "--seed", 3,
               "--quiet", "--json", scores_json, "--features-json", samples_json)
    assert done.returncode == 0, done.stderr
    clip = metric_features(clip_json)[0]
    samples = metric_features(samples_json)
    report = json.loads(scores_json.read_text())["report"]
    assert clip.shape[1] == 31 * 6 + 2 and len(samples) == 3 and samples[0].shape[0] == 80

    made_by = np.zeros(len(clip) - 30 + 1)
    for i, (sample, scores) in enumerate(zip(samples, report["per_sample"])):
        covered = nearest_windows(clip, sample, 30) < 2.0
        made_by += covered
        assert abs(scores["coverage"] - 100 * covered.mean()) < 1e-12, i
        assert abs(scores["global_diversity"] - patched_nn(sample, clip)) < 1e-12, i
        assert abs(scores["local_diversity"] - nearest_windows(sample, clip, 15).mean()) < 1e-12, i
        previous = samples[i - 1]
        inter = np.linalg.norm(sample - previous) / len(sample)
        assert abs(scores["inter_diversity"] - inter) < 1e-12, i
        assert abs(scores["intra_diversity"] - intra(sample)) < 1e-12, i
    # Each clip window's share of the samples that make it.
    assert np.abs(np.array(report["clip_window_coverage"]) - 100 * made_by / len(samples)).max() < 1e-12
    gap = abs(np.mean([intra(s) for s in samples]) - intra(clip))
    assert abs(report["intra_diversity_diff"] - gap) < 1e-12


def rotations(path):
    """Frames x every 6D rotation component of each motion in the file (f32 widened)."""
    data = json.loads(path.read_text())
    keep = [i for i, name in enumerate(data["columns"]) if ".rot6d[" in name]
    return [np.asarray(sample, dtype=np.float32).astype(np.float64)[keep].T for sample in data["samples"]]


def longest_replay(sample, clip, tolerance):
    """The longest run of sample frames s..s+L matching clip frames k..k+L, each pair within
    `tolerance` root-mean-square per column: every start pair tried, walked frame by frame."""
    rms = np.sqrt(((sample[:, None, :] - clip[None, :, :]) ** 2).mean(axis=2))
    close = rms <= tolerance
    best = 0
    for s in range(len(sample)):
        for k in range(len(clip)):
            n = 0
            while s + n < len(sample) and k + n < len(clip) and close[s + n, k + n]:
                n += 1
            best = max(best, n)
    return best


def longest_hold(clip, tolerance):
    """The most consecutive clip frames within `tolerance` root-mean-square per column of one clip
    frame: every pose tried against every run of frames, walked frame by frame."""
    best = 0
    for pose in clip:
        near = np.sqrt(((clip - pose) ** 2).mean(axis=1)) <= tolerance
        for start in range(len(clip)):
            n = 0
            while start + n < len(clip) and near[start + n]:
                n += 1
            best = max(best, n)
    return best


def test_eval_replay_matches_a_naive_search(tmp_path):
    """The replay figure against every start pair walked in numpy, at the default tolerance and
    at a loose one under which the tiny model's samples do copy stretches of the clip."""
    clip_json, samples_json = tmp_path / "clip.json", tmp_path / "samples.json"
    run = lambda *a: subprocess.run([str(SINMDM), *map(str, a)], capture_output=True, text=True)  # noqa: E731
    done = run("encode", WALK, "-m", MODEL, "-o", clip_json)
    assert done.returncode == 0, done.stderr
    clip = rotations(clip_json)[0]
    longest, holds, reversed_runs = {}, {}, {}
    for tolerance in (0.05, 0.6):
        scores_json = tmp_path / f"scores_{tolerance}.json"
        done = run("eval", "-m", MODEL, "--clip", WALK, "--samples", 3, "--frames", 80, "--steps", 5,
                   "--seed", 3, "--quiet", "--json", scores_json, "--features-json", samples_json,
                   "--replay-tolerance", tolerance)
        assert done.returncode == 0, done.stderr
        assert "replay:" in done.stdout
        replay = json.loads(scores_json.read_text())["replay"]
        samples = rotations(samples_json)
        expected = [longest_replay(s, clip, tolerance) for s in samples]
        assert replay["longest_frames"] == expected, tolerance
        fps = replay["fps"]
        assert abs(replay["mean_seconds"] - np.mean(expected) / fps) < 1e-12
        assert abs(replay["max_seconds"] - max(expected) / fps) < 1e-12
        hold = longest_hold(clip, tolerance)
        assert replay["clip_hold_frames"] == hold, tolerance
        assert abs(replay["clip_hold_seconds"] - hold / fps) < 1e-12
        backwards = longest_replay(clip[::-1], clip, tolerance)
        assert replay["clip_backwards_frames"] == backwards, tolerance
        assert abs(replay["clip_backwards_seconds"] - backwards / fps) < 1e-12
        holds[tolerance] = hold
        reversed_runs[tolerance] = backwards
        longest[tolerance] = expected
    # The loose tolerance finds copies, so the comparison above checked real runs; and the walk
    # stands still for a while before it walks, so at the default tolerance its hold is a real
    # run of frames, neither one frame nor the whole clip; and this clip played backwards
    # matches itself over more than one frame (a hold alone would not make it so), so the
    # backwards figure was checked on a real run too.
    assert max(longest[0.6]) >= 2, longest
    assert 2 <= holds[0.05] < len(clip), holds
    assert 2 <= reversed_runs[0.05] < len(clip), reversed_runs

"""`sinmdm eval`'s kinematic fidelity (how the samples move against the clip) against a naive
numpy version written from its definition, on positions computed in numpy from the BVH files
of the same samples (written by `sinmdm generate`) and of the clip; the distribution distance
is scipy's, an independent implementation of the 1-Wasserstein distance."""

import json
import subprocess

import numpy as np
import onnx
from scipy.stats import wasserstein_distance

from conftest import ROOT, SINMDM
from test_feet_metrics import axis_rotation, positions, read_bvh

MODEL = ROOT / "tests" / "data" / "models" / "walk_tiny.onnx"
WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"


def root_rotation(path, every=1):
    """The root joint's rotation per frame: its rotation channels composed in their order."""
    joints, motion = read_bvh(path)
    motion = motion[::every]
    rotation = np.tile(np.eye(3), (len(motion), 1, 1))
    for column, name in enumerate(joints[0]["channels"]):
        if name.endswith("rotation"):
            rotation = rotation @ axis_rotation(name[0], motion[:, column])
    return rotation


def body_kinematics(path, height, fps, every=1):
    """Per frame pair the mean speed, per inner frame the mean acceleration, of every joint but
    the root relative to the root in its own frame, in skeleton heights."""
    joints, _, _, _ = positions(path, every)
    r = root_rotation(path, every)
    rel = np.einsum("fji,fkj->fki", r, joints[:, 1:] - joints[:, :1]) / height
    speeds = np.linalg.norm(np.diff(rel, axis=0), axis=2).mean(axis=1) * fps
    accelerations = np.linalg.norm(rel[2:] - 2 * rel[1:-1] + rel[:-2], axis=2).mean(axis=1) * fps**2
    return speeds, accelerations


def fidelity(clip, samples):
    (cs, ca), (ss, sa) = clip, samples
    still = 0.25 * np.median(cs)
    return {
        "clip_still_share": np.mean(cs < still),
        "still_share": np.mean(ss < still),
        "speed_ratios": [np.percentile(ss, p) / np.percentile(cs, p) for p in (25, 50, 90)],
        "speed_distance": wasserstein_distance(ss, cs) / cs.mean(),
        "acceleration_distance": wasserstein_distance(sa, ca) / ca.mean(),
    }


def test_eval_kinematic_fidelity_matches_the_numpy_definition(tmp_path):
    meta = json.loads(next(e.value for e in onnx.load(str(MODEL)).metadata_props
                           if e.key == "sinmdm.metadata"))
    height, fps = meta["layout"]["skeleton_height"], meta["layout"]["fps"]
    assert fps == 30

    scores_json = tmp_path / "scores.json"
    common = ["--seed", 5, "--steps", 4, "-m", MODEL]
    run = lambda *a: subprocess.run([str(SINMDM), *map(str, a)], capture_output=True, text=True)  # noqa: E731
    done = run("eval", *common, "--clip", WALK, "--samples", 3, "--quiet", "--json", scores_json)
    assert done.returncode == 0, done.stderr
    assert "| nearly still frames (%) |" in done.stdout
    scores = json.loads(scores_json.read_text())
    report, frames = scores["kinematics"], scores["frames"]

    # The clip at the model's 30 fps: the 120 fps file's every 4th frame.
    clip = body_kinematics(WALK, height, fps, every=4)
    expected_clip_still = np.mean(clip[0] < 0.25 * np.median(clip[0]))
    assert abs(report["clip"]["still_share"] - expected_clip_still) <= 2.0 / len(clip[0])
    for p, value in zip((25, 50, 90), report["clip"]["speed_percentiles"]):
        assert abs(value - np.percentile(clip[0], p)) <= 1e-3 * value, (p, value)

    for feet_mode in ["raw", "planted"]:
        done = run("generate", *common, "--count", 3, "--frames", frames, "--quiet",
                   "--feet", feet_mode, "-o", tmp_path / f"{feet_mode}.bvh")
        assert done.returncode == 0, done.stderr
        pooled = [body_kinematics(tmp_path / f"{feet_mode}_{i:03d}.bvh", height, fps) for i in range(3)]
        samples = (np.concatenate([p[0] for p in pooled]), np.concatenate([p[1] for p in pooled]))
        assert len(samples[0]) == 3 * (frames - 1)
        expected = fidelity(clip, samples)
        rust = report[feet_mode]
        pairs = len(samples[0])
        assert abs(rust["still_share"] - expected["still_share"]) <= 2.0 / pairs, (rust, expected)
        for mine, theirs in zip(rust["speed_ratios"], expected["speed_ratios"]):
            assert abs(mine - theirs) <= 2e-3 * theirs, (rust, expected)
        for key in ("speed_distance", "acceleration_distance"):
            assert abs(rust[key] - expected[key]) <= 2e-3 * expected[key] + 1e-6, (key, rust, expected)
        # A 4-step sample of a tiny model does not move like the walk: the figures are not
        # trivially those of the clip itself.
        assert expected["acceleration_distance"] > 0.1, expected

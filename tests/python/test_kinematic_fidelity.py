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


def carrying_root(path, world):
    """The joint that carries the body: from the top joint down, a joint that never moves and
    has one child passes the role to it (a still ground joint above the hips)."""
    joints, _ = read_bvh(path)
    root = 0
    while True:
        children = [k for k, joint in enumerate(joints) if joint["parent"] == root]
        if len(children) != 1 or np.ptp(world[:, root], axis=0).max() > 1e-9:
            return root
        root = children[0]


def root_rotation(path, root, every=1):
    """Joint `root`'s world rotation per frame: the rotation channels of it and the joints
    above it composed in their order, from the top."""
    joints, motion = read_bvh(path)
    motion = motion[::every]
    first_column = np.cumsum([0] + [len(j["channels"]) for j in joints])
    chain = [root]
    while joints[chain[-1]]["parent"] is not None:
        chain.append(joints[chain[-1]]["parent"])
    rotation = np.tile(np.eye(3), (len(motion), 1, 1))
    for joint in reversed(chain):
        for k, name in enumerate(joints[joint]["channels"]):
            if name.endswith("rotation"):
                rotation = rotation @ axis_rotation(name[0], motion[:, first_column[joint] + k])
    return rotation


def body_kinematics(path, height, fps, every=1):
    """Per frame pair the mean speed, per inner frame the mean acceleration, of every joint
    below the root that carries the body, relative to it in its own frame, in skeleton
    heights."""
    joints, _, _, _ = positions(path, every)
    root = carrying_root(path, joints)
    r = root_rotation(path, root, every)
    rel = np.einsum("fji,fkj->fki", r, joints[:, root + 1:] - joints[:, root:root + 1]) / height
    speeds = np.linalg.norm(np.diff(rel, axis=0), axis=2).mean(axis=1) * fps
    accelerations = np.linalg.norm(rel[2:] - 2 * rel[1:-1] + rel[:-2], axis=2).mean(axis=1) * fps**2
    return speeds, accelerations


def turn_rates(path, every=1, fps=30.0, up=(0.0, 1.0, 0.0)):
    """Degrees per second the carrying root's heading turns between frames: the root axis that
    lies flattest on the ground (normal to `up`) over the motion, projected on it."""
    joints, _, _, _ = positions(path, every)
    r = root_rotation(path, carrying_root(path, joints), every)
    up = np.asarray(up, dtype=float)
    flats = [r[:, :, k] - np.outer(r[:, :, k] @ up, up) for k in range(3)]
    flat = max(flats, key=lambda f: np.linalg.norm(f, axis=1).sum())
    a, b = flat[:-1], flat[1:]
    return np.degrees(np.abs(np.arctan2(np.cross(a, b) @ up, (a * b).sum(axis=1)))) * fps


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

        # How fast the whole body turns, beside the body's figures.
        clip_turns = turn_rates(WALK, every=4)
        turns = np.concatenate([turn_rates(tmp_path / f"{feet_mode}_{i:03d}.bvh") for i in range(3)])
        turning = scores["kinematics"]["turning"]
        # The clip is scored as the model encodes it (f32 features), so within 1 %.
        assert abs(turning["clip"]["most"] - clip_turns.max()) <= 1e-2 * clip_turns.max(), turning
        assert abs(turning["clip"]["fast"] - np.percentile(clip_turns, 99)) <= 1e-2 * clip_turns.max()
        mine = turning[feet_mode]
        assert abs(mine["fast"] - np.percentile(turns, 99)) <= 2e-3 * max(turns.max(), 1.0), (mine, feet_mode)
        faster = np.mean(turns > max(turning["clip"]["most"], 1.0))
        assert abs(mine["faster_than_clip"] - faster) <= 2.0 / len(turns), (mine, faster)

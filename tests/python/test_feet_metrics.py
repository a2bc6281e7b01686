"""`sinmdm eval`'s feet and smoothness figures (SPEC section 9) against the numpy reference in
`python/sinmdm_reference/feet.py`, on positions computed here in numpy from the BVH files of the
same samples (written by `sinmdm generate`) and of the clip; the joints of that numpy forward
kinematics are checked against an independent reader (bvhio) first."""

import json
import subprocess
import sys

import numpy as np
import onnx

from conftest import ROOT, SINMDM, bvhio_joint_positions

from sinmdm_reference import feet

MODEL = ROOT / "tests" / "data" / "models" / "walk_tiny.onnx"
WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"


def read_bvh(path):
    """Joints (name, parent, offset, channels, End Site offset or None) and the motion values."""
    joints, stack, motion, in_end, lines = [], [], [], False, path.read_text().splitlines()
    for n, line in enumerate(lines):
        words = line.split()
        if not words:
            continue
        if words[0] in ("ROOT", "JOINT"):
            joints.append({"name": words[1], "parent": stack[-1] if stack else None,
                           "channels": [], "end": None})
        elif words[0] == "End":
            in_end = True
        elif words[0] == "{":
            stack.append(-1 if in_end else len(joints) - 1)
        elif words[0] == "}":
            stack.pop()
            in_end = False
        elif words[0] == "OFFSET":
            offset = np.array([float(v) for v in words[1:4]])
            if stack[-1] == -1:
                joints[stack[-2]]["end"] = offset
            else:
                joints[stack[-1]]["offset"] = offset
        elif words[0] == "CHANNELS":
            joints[stack[-1]]["channels"] = words[2:]
        elif words[0] == "MOTION":
            motion = np.array([[float(v) for v in l.split()] for l in lines[n + 3:] if l.strip()])
            break
    return joints, motion


def axis_rotation(axis, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    i, j = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}[axis]
    m = np.tile(np.eye(3), (len(degrees), 1, 1))
    m[:, i, i], m[:, i, j], m[:, j, i], m[:, j, j] = c, -s, s, c
    return m


def positions(path, every=1):
    """Forward kinematics in numpy, written from the BVH definition: (joints [F, J, 3], End
    Sites [F, E, 3], joint names, End Site owner names). Rotations compose in the order the
    channels are listed."""
    joints, motion = read_bvh(path)
    motion = motion[::every]
    frames = len(motion)
    world_p, world_r, column = [], [], 0
    for joint in joints:
        local_p = np.tile(joint["offset"], (frames, 1))
        local_r = np.tile(np.eye(3), (frames, 1, 1))
        for name in joint["channels"]:
            values = motion[:, column]
            column += 1
            if name.endswith("position"):
                local_p[:, "XYZ".index(name[0])] = values
            else:
                local_r = local_r @ axis_rotation(name[0], values)
        parent = joint["parent"]
        if parent is None:
            world_p.append(local_p)
            world_r.append(local_r)
        else:
            world_p.append(world_p[parent] + np.einsum("fij,fj->fi", world_r[parent], local_p))
            world_r.append(world_r[parent] @ local_r)
    sites = [world_p[i] + np.einsum("fij,j->fi", world_r[i], j["end"])
             for i, j in enumerate(joints) if j["end"] is not None]
    return (np.stack(world_p, axis=1), np.stack(sites, axis=1), [j["name"] for j in joints],
            [j["name"] for j in joints if j["end"] is not None])


def contact_points(joints, sites, names, owners, contact_names):
    cols = []
    for name in contact_names:
        if name in owners:
            cols.append(sites[:, owners.index(name)])
        else:
            cols.append(joints[:, names.index(name)])
    return np.stack(cols, axis=1)


def test_eval_feet_figures_match_the_numpy_reference(tmp_path):
    meta = json.loads(next(e.value for e in onnx.load(str(MODEL)).metadata_props
                           if e.key == "sinmdm.metadata"))
    layout = meta["layout"]
    assert layout.get("up", "+Y") == "+Y"
    skeleton = [j["name"] for j in layout["skeleton"]["joints"]]
    contact_names = [skeleton[j] for j in layout["contact_joints"]]
    height, fps = layout["skeleton_height"], layout["fps"]
    assert contact_names and fps == 30

    scores_json = tmp_path / "scores.json"
    common = ["--seed", 3, "--steps", 4, "-m", MODEL]
    run = lambda *a: subprocess.run([str(SINMDM), *map(str, a)], capture_output=True, text=True)  # noqa: E731
    done = run("eval", *common, "--clip", WALK, "--samples", 2, "--quiet", "--json", scores_json)
    assert done.returncode == 0, done.stderr
    assert "| skating ratio (%) ↓ |" in done.stdout
    report = json.loads(scores_json.read_text())["feet"]
    frames = json.loads(scores_json.read_text())["frames"]
    for feet_mode in ["raw", "planted"]:
        done = run("generate", *common, "--count", 2, "--frames", frames, "--quiet",
                   "--feet", feet_mode, "-o", tmp_path / f"{feet_mode}.bvh")
        assert done.returncode == 0, done.stderr

    # Our numpy forward kinematics agrees with bvhio on the joints (End Sites are ours alone).
    theirs, their_names = bvhio_joint_positions(WALK)
    mine, _, names, _ = positions(WALK)
    assert names == their_names
    assert np.abs(mine - theirs).max() < 1e-3
    # The clip at the model's 30 fps: the 120 fps file's every 4th frame.
    cj, cs, names, owners = positions(WALK, every=4)
    clip_contacts = contact_points(cj, cs, names, owners, contact_names)
    ground = feet.ground_level(clip_contacts)
    clip_points = np.concatenate([cj, cs], axis=1)
    expected_clip = feet.scores(clip_points, cj, clip_contacts, ground, height, fps)

    def close(rust, numpy, pairs):
        assert abs(rust["skating_ratio"] - numpy["skating_ratio"]) <= 2.0 / pairs, (rust, numpy)
        assert abs(rust["max_penetration"] - numpy["max_penetration"]) < 1e-4, (rust, numpy)
        assert abs(rust["penetrating_frames"] - numpy["penetrating_frames"]) <= 2.0 / pairs, (rust, numpy)
        assert abs(rust["jitter"] - numpy["jitter"]) <= 1e-3 * numpy["jitter"] + 1e-6, (rust, numpy)

    close(report["clip"], expected_clip, cj.shape[0] - 1)
    skated = {}
    for feet_mode in ["raw", "planted"]:
        skated[feet_mode] = 0.0
        for i, rust in enumerate(report[feet_mode]["per_sample"]):
            sj, ss, names, owners = positions(tmp_path / f"{feet_mode}_{i:03d}.bvh")
            assert sj.shape[0] == frames
            contacts = contact_points(sj, ss, names, owners, contact_names)
            expected = feet.scores(np.concatenate([sj, ss], axis=1), sj, contacts, ground, height, fps)
            close(rust, expected, frames - 1)
            skated[feet_mode] += expected["skating_ratio"]
    # The figures are not all trivially zero: a 4-step sample of a tiny model skates, and
    # planting its feet (measured here by numpy on the written files) skates less.
    assert skated["raw"] > 0 and expected_clip["jitter"] > 0
    assert skated["planted"] < skated["raw"], skated

"""How far each clip's body moves within the network's view, against how far its poses spread:
a candidate for a rule that reads the clip's time scale (issue: motion that moves like the clip).

For every BVH clip named: the body's joints relative to the root joint, in its frame (numpy
forward kinematics from the BVH definition); the pose spread (RMS distance of the joints from
their mean positions over the clip); the mean joint displacement over a lag of LAG seconds (the
network's view: 23 frames, 0.77 s at 30 fps; 2.3 s at 10 fps), as a share of the spread; and the
median joint speed in spreads per second. Scale-free: units cancel.
Usage: .venv/bin/python lab/scripts/time_scale.py CLIP.bvh [CLIP.bvh ...]
"""
import sys
from pathlib import Path

import numpy as np


def read_bvh(path):
    joints, stack, lines, in_end = [], [], Path(path).read_text().splitlines(), False
    for n, line in enumerate(lines):
        words = line.split()
        if not words:
            continue
        key = words[0]
        if key in ("ROOT", "JOINT"):
            joints.append({"parent": stack[-1] if stack else None, "channels": []})
        elif key == "End":
            in_end = True
        elif key == "{":
            stack.append(-1 if in_end else len(joints) - 1)
        elif key == "}":
            stack.pop()
            in_end = False
        elif key == "OFFSET" and stack[-1] != -1:
            joints[stack[-1]]["offset"] = np.array([float(v) for v in words[1:4]])
        elif key == "CHANNELS":
            joints[stack[-1]]["channels"] = words[2:]
        elif key == "Frame" and words[1] == "Time:":
            frame_time = float(words[2])
            motion = np.array([[float(v) for v in l.split()] for l in lines[n + 1:] if l.strip()])
            return joints, motion, 1.0 / frame_time
    raise ValueError(f"{path}: no MOTION block")


def rotation(axis, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    i, j = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}[axis]
    m = np.tile(np.eye(3), (len(degrees), 1, 1))
    m[:, i, i], m[:, i, j], m[:, j, i], m[:, j, j] = c, -s, s, c
    return m


def body(path):
    """Joints but the root, relative to the root in its own frame: [frames, joints, 3], fps."""
    joints, motion, fps = read_bvh(path)
    frames, column, world_p, world_r = len(motion), 0, [], []
    for joint in joints:
        p = np.tile(joint["offset"], (frames, 1))
        r = np.tile(np.eye(3), (frames, 1, 1))
        for name in joint["channels"]:
            if name.endswith("position"):
                p[:, "XYZ".index(name[0])] = motion[:, column]
            else:
                r = r @ rotation(name[0], motion[:, column])
            column += 1
        if joint["parent"] is None:
            world_p.append(p)
            world_r.append(r)
        else:
            parent = joint["parent"]
            world_p.append(world_p[parent] + np.einsum("fij,fj->fi", world_r[parent], p))
            world_r.append(world_r[parent] @ r)
    # The joint that carries the body: a still joint with one child (a ground joint above the
    # hips) passes the role down, as the runtime's travelling_root does.
    root = 0
    while True:
        children = [k for k, joint in enumerate(joints) if joint["parent"] == root]
        if len(children) != 1 or np.ptp(world_p[root], axis=0).max() > 1e-9:
            break
        root = children[0]
    below = [k for k in range(len(joints)) if k > root]
    p, r = np.stack(world_p, axis=1), world_r[root]
    relative = np.einsum("fji,fkj->fki", r, p[:, below] - p[:, root:root + 1])
    return relative, fps


def main(paths):
    print("| clip | fps | seconds | median speed (spreads/s) | moved in 0.77 s | moved in 2.3 s |")
    print("|---|---|---|---|---|---|")
    for path in paths:
        pose, fps = body(path)
        spread = np.sqrt(((pose - pose.mean(axis=0)) ** 2).sum(axis=2).mean())
        speed = np.linalg.norm(np.diff(pose, axis=0), axis=2).mean(axis=1) * fps / spread

        def moved(seconds):
            lag = max(1, round(seconds * fps))
            return np.linalg.norm(pose[lag:] - pose[:-lag], axis=2).mean() / spread

        print(f"| {Path(path).stem} | {fps:.0f} | {len(pose) / fps:.1f} | {np.median(speed):.2f} "
              f"| {moved(23 / 30):.2f} | {moved(2.3):.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:])

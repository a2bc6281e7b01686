"""Feet and smoothness metrics (SPEC section 9) in numpy, from global positions.

Written from the definitions, independently of the runtime's `sinmdm-eval` crate, so the two
check each other. Positions are arrays [frames, points, 3] in a Y-up frame; `contacts` are the
contact points (a contact joint's End Site when it has one), `joints` the joints only, `points`
the body's joints and End Sites (a static container above the motion root, such as a root bone
left at the world origin, is no part of the body: SPEC section 2).
"""

import numpy as np

GROUND_BAND = 0.05
SKATING_SPEED = 0.3
PENETRATION_TOLERANCE = 0.01
GROUND_PERCENTILE = 5.0
SPEED_WINDOW = 5


def ground_level(contacts):
    """The 5th percentile over frames of the lowest contact point's height."""
    return float(np.percentile(contacts[:, :, 1].min(axis=1), GROUND_PERCENTILE))


def skating_ratio(contacts, ground, height, fps):
    pairs = contacts.shape[0] - 1
    if pairs <= 0:
        return 0.0
    step = contacts[1:] - contacts[:-1]
    speed = np.hypot(step[:, :, 0], step[:, :, 2]) * fps  # [pairs, contacts]
    half = SPEED_WINDOW // 2
    average = np.stack([speed[max(0, i - half): min(pairs, i + half + 1)].mean(axis=0)
                        for i in range(pairs)])
    low = contacts[:, :, 1] - ground < GROUND_BAND * height
    on_ground = low[:-1] & low[1:]
    skating = on_ground & (speed > SKATING_SPEED * height) & (average > SKATING_SPEED * height)
    return float(skating.any(axis=1).mean())


def penetration(points, ground, height):
    """(deepest point below the ground in H, share of frames with a point 0.01 H below it)."""
    depth = np.maximum(0.0, ground - points[:, :, 1]) / height
    below = (points[:, :, 1] < ground - PENETRATION_TOLERANCE * height).any(axis=1)
    return float(depth.max()), float(below.mean())


def jitter(joints, height, fps):
    if joints.shape[0] < 3:
        return 0.0
    accel = joints[2:] - 2.0 * joints[1:-1] + joints[:-2]
    return float(np.linalg.norm(accel, axis=2).mean() * fps * fps / height)


def scores(points, joints, contacts, ground, height, fps):
    deepest, frames = penetration(points, ground, height)
    return {
        "skating_ratio": skating_ratio(contacts, ground, height, fps),
        "max_penetration": deepest,
        "penetrating_frames": frames,
        "jitter": jitter(joints, height, fps),
    }

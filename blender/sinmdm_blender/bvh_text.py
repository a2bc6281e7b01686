"""BVH text in and out, with numpy only (no bpy), so that the rig code can be checked outside
Blender too.

A skeleton here is world-aligned: every joint's rest frame has the axes of the file, so a joint's
rotation channels are the change of its bone's direction from rest. Rotation channels are written
`Zrotation Yrotation Xrotation` (R = Rz Ry Rx); any order is read.
"""

import numpy as np


class Skeleton:
    """Joint names, parents (-1 for the root), rest offsets from the parent (J x 3), the End Site
    offset of each leaf joint, and each joint's channel names."""

    def __init__(self, names, parents, offsets, end_sites, channels):
        self.names = list(names)
        self.parents = list(parents)
        self.offsets = np.asarray(offsets, dtype=np.float64).reshape(-1, 3)
        self.end_sites = dict(end_sites)
        self.channels = [list(c) for c in channels]


def _axis_rotation(axis, degrees):
    """Rotation matrices (N x 3 x 3) about one axis, for N angles in degrees."""
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(a.shape + (3, 3))
    i, j = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}[axis]
    k = 3 - i - j
    m[..., k, k] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -s
    m[..., j, i] = s
    return m


def matrices_to_zyx_degrees(r):
    """Angles (z, y, x) in degrees with r = Rz(z) Ry(y) Rx(x), for rotation matrices (... x 3 x 3)."""
    sy = np.clip(-r[..., 2, 0], -1.0, 1.0)
    y = np.arcsin(sy)
    cy = np.cos(y)
    regular = cy > 1e-9
    x = np.where(regular, np.arctan2(r[..., 2, 1], r[..., 2, 2]), 0.0)
    z = np.where(regular, np.arctan2(r[..., 1, 0], r[..., 0, 0]), np.arctan2(-r[..., 0, 1], r[..., 1, 1]))
    return np.degrees(np.stack([z, y, x], axis=-1))


def write(skeleton, root_positions, local_rotations, fps):
    """BVH text: the root's positions (F x 3) and every joint's rotation relative to its parent
    (F x J x 3 x 3), at `fps` frames per second. The root's OFFSET is zero: its channels hold its
    position, so readers that add the OFFSET and readers that do not agree."""
    names, parents = skeleton.names, skeleton.parents
    children = {j: [c for c, p in enumerate(parents) if p == j] for j in range(len(names))}
    lines = ["HIERARCHY"]
    order = []  # the joints as the hierarchy lists them, which is the motion's channel order

    def joint(j, depth):
        order.append(j)
        pad = "\t" * depth
        lines.append(f"{pad}{'ROOT' if parents[j] < 0 else 'JOINT'} {names[j]}")
        lines.append(pad + "{")
        off = (0.0, 0.0, 0.0) if parents[j] < 0 else skeleton.offsets[j]
        lines.append(f"{pad}\tOFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        if parents[j] < 0:
            lines.append(f"{pad}\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation")
        else:
            lines.append(f"{pad}\tCHANNELS 3 Zrotation Yrotation Xrotation")
        for c in children[j]:
            joint(c, depth + 1)
        if not children[j]:
            end = skeleton.end_sites.get(j, (0.0, 0.0, 0.0))
            lines.append(f"{pad}\tEnd Site")
            lines.append(pad + "\t{")
            lines.append(f"{pad}\t\tOFFSET {end[0]:.6f} {end[1]:.6f} {end[2]:.6f}")
            lines.append(pad + "\t}")
        lines.append(pad + "}")

    joint(parents.index(-1), 0)
    frames = np.asarray(root_positions).shape[0]
    angles = matrices_to_zyx_degrees(np.asarray(local_rotations))
    lines += ["MOTION", f"Frames: {frames}", f"Frame Time: {1.0 / fps:.8f}"]
    for f in range(frames):
        values = list(root_positions[f])
        for j in order:
            values += list(angles[f, j])
        lines.append(" ".join(f"{v:.6f}" for v in values))
    return "\n".join(lines) + "\n"


def read(text):
    """(skeleton, motion values F x channels, frame time) of a BVH text; joints in file order."""
    tokens = text.split()
    names, parents, offsets, channels, end_sites = [], [], [], [], {}
    stack = []
    i = 0
    while tokens[i] != "MOTION":
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            names.append(tokens[i + 1])
            parents.append(stack[-1] if stack else -1)
            offsets.append((0.0, 0.0, 0.0))
            channels.append([])
            stack.append(len(names) - 1)
            i += 2
        elif t == "End":
            # End Site { OFFSET x y z }
            end_sites[stack[-1]] = tuple(float(v) for v in tokens[i + 4 : i + 7])
            i += 8
        elif t == "OFFSET":
            offsets[stack[-1]] = tuple(float(v) for v in tokens[i + 1 : i + 4])
            i += 4
        elif t == "CHANNELS":
            n = int(tokens[i + 1])
            channels[stack[-1]] = tokens[i + 2 : i + 2 + n]
            i += 2 + n
        elif t == "}":
            stack.pop()
            i += 1
        else:
            i += 1
    frames = int(tokens[i + 2])
    frame_time = float(tokens[i + 5])
    width = sum(len(c) for c in channels)
    values = np.array(tokens[i + 6 : i + 6 + frames * width], dtype=np.float64).reshape(frames, width)
    return Skeleton(names, parents, offsets, end_sites, channels), values, frame_time


def forward_kinematics(skeleton, values):
    """Every joint's rotation from rest in the file's axes (F x J x 3 x 3) and position (F x J x 3).
    A joint's position channels replace its OFFSET; the root's are added to it."""
    frames = values.shape[0]
    count = len(skeleton.names)
    rotations = np.zeros((frames, count, 3, 3))
    positions = np.zeros((frames, count, 3))
    column = 0
    for j in range(count):
        local = np.broadcast_to(np.eye(3), (frames, 3, 3)).copy()
        translation = np.broadcast_to(skeleton.offsets[j], (frames, 3)).copy()
        moved = np.zeros((frames, 3))
        has_position = False
        for name in skeleton.channels[j]:
            v = values[:, column]
            column += 1
            if name.endswith("position"):
                moved[:, "XYZ".index(name[0])] = v
                has_position = True
            else:
                local = local @ _axis_rotation(name[0], v)
        p = skeleton.parents[j]
        if has_position:
            translation = moved + (translation if p < 0 else 0.0)
        if p < 0:
            rotations[:, j] = local
            positions[:, j] = translation
        else:
            rotations[:, j] = rotations[:, p] @ local
            positions[:, j] = positions[:, p] + np.einsum("fab,fb->fa", rotations[:, p], translation)
    return rotations, positions

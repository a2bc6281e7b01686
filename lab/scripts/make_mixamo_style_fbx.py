"""Writes a Mixamo-style ASCII FBX 7.4 fixture from a BVH clip: bone names with a 'mixamorig:'
namespace, centimetres, Y up, every bone's rest orientation in its PreRotation (along the bone,
as Mixamo's rigs have it), a PostRotation on some bones, and a still '_End' leaf bone at every
End Site.

FBX composes a bone's rotation as PreRotation * Lcl Rotation * PostRotation^-1 (each an XYZ
Euler rotation, x applied first). With rest world orientation A_j of bone j (parent p) and the
BVH's local rotation R_j(t), the file keeps the bone frame rigidly attached to the BVH joint:
world(t) = BVH world(t) * A_j. So PreRotation = A_p^T A_j and Lcl Rotation(t) =
A_j^T R_j(t) A_j Post_j, translations A_p^T offset_j in centimetres.

The fixture is checked by a reader that is not ours (three.js's FBXLoader puts every bone where
the BVH does, tests/python/test_fbx_independent_readers.py) before our reader is tested on it.

    python3 lab/scripts/make_mixamo_style_fbx.py CLIP.bvh OUT.fbx [--seconds 1] [--cm-per-unit 5.64]
"""

import argparse
import math

import numpy as np

KTIME_PER_SECOND = 46186158000


def parse_bvh(path):
    """Joints (name, parent, offset, channels, end site) and the frames' channel values."""
    tokens = open(path).read().split()
    joints, stack, i = [], [], 0
    while tokens[i] != "MOTION":
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            joints.append({"name": tokens[i + 1], "parent": stack[-1] if stack else None,
                           "offset": None, "channels": [], "end": None})
            i += 2
        elif t == "End":
            i += 2
            assert tokens[i] == "{" and tokens[i + 1] == "OFFSET"
            joints[stack[-1]]["end"] = np.array([float(x) for x in tokens[i + 2:i + 5]])
            i += 6
            continue
        elif t == "{":
            stack.append(len(joints) - 1)
            i += 1
        elif t == "}":
            stack.pop()
            i += 1
        elif t == "OFFSET":
            joints[stack[-1]]["offset"] = np.array([float(x) for x in tokens[i + 1:i + 4]])
            i += 4
        elif t == "CHANNELS":
            n = int(tokens[i + 1])
            joints[stack[-1]]["channels"] = tokens[i + 2:i + 2 + n]
            i += 2 + n
        else:
            i += 1
    frames = int(tokens[i + 2])
    frame_time = float(tokens[i + 5])
    values = np.array([float(x) for x in tokens[i + 6:]]).reshape(frames, -1)
    return joints, values, frame_time


def axis_rotation(axis, degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    if axis == "X":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "Y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def joint_motion(joint, row):
    """A joint's local rotation and position channels from its values in one frame."""
    rotation, position = np.eye(3), None
    for channel, value in zip(joint["channels"], row):
        if channel.endswith("rotation"):
            rotation = rotation @ axis_rotation(channel[0], value)
        else:
            position = position if position is not None else np.zeros(3)
            position["XYZ".index(channel[0])] = value
    return rotation, position


def euler_xyz(r):
    """Degrees (x, y, z) with r = Rz Ry Rx."""
    y = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    x = math.atan2(r[2, 1], r[2, 2])
    z = math.atan2(r[1, 0], r[0, 0])
    return np.degrees([x, y, z])


def from_euler_xyz(d):
    return axis_rotation("Z", d[2]) @ axis_rotation("Y", d[1]) @ axis_rotation("X", d[0])


def along(direction, previous):
    """A rotation whose Y axis points along `direction`, its X axis as close to `previous`'s as
    can be (Mixamo's bones point down their Y axis)."""
    y = direction / np.linalg.norm(direction)
    x = previous[:, 0] - y * (previous[:, 0] @ y)
    if np.linalg.norm(x) < 1e-6:
        x = previous[:, 2] - y * (previous[:, 2] @ y)
    x /= np.linalg.norm(x)
    return np.column_stack([x, y, np.cross(x, y)])


def unwrap(angles):
    """Euler angles over frames made continuous (no 360-degree jumps between keys)."""
    out = angles.copy()
    for f in range(1, len(out)):
        out[f] = out[f - 1] + (out[f] - out[f - 1] + 180.0) % 360.0 - 180.0
    return out


class Ids:
    def __init__(self):
        self.next = 100000

    def __call__(self):
        self.next += 1
        return self.next


def numbers(values):
    return ",".join("%.9g" % v for v in values)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("bvh")
    parser.add_argument("out")
    parser.add_argument("--seconds", type=float, default=1.0)
    parser.add_argument("--cm-per-unit", type=float, default=5.64)
    args = parser.parse_args()

    joints, values, frame_time = parse_bvh(args.bvh)
    fps = round(1.0 / frame_time)
    frames = min(len(values), int(round(args.seconds * fps)) + 1)
    values = values[:frames]
    scale = args.cm_per_unit

    # Rest orientation of every bone: along its first child (or End Site), else its parent's.
    children = {j: [k for k, o in enumerate(joints) if o["parent"] == j] for j in range(len(joints))}
    rest = []
    for j, joint in enumerate(joints):
        previous = rest[joint["parent"]] if joint["parent"] is not None else axis_rotation("X", 90.0)
        if children[j]:
            direction = joints[children[j][0]]["offset"]
        elif joint["end"] is not None:
            direction = joint["end"]
        else:
            direction = None
        if direction is not None and np.linalg.norm(direction) > 1e-9:
            rest.append(along(direction, previous))
        else:
            rest.append(previous)
    post = [axis_rotation("Z", 15.0) @ axis_rotation("X", -10.0) if j % 3 == 1 else np.eye(3)
            for j in range(len(joints))]

    # Per frame, per joint: FBX Lcl Rotation (degrees XYZ) and, for the root, Lcl Translation.
    columns, at = [], 0
    for joint in joints:
        columns.append((at, at + len(joint["channels"])))
        at += len(joint["channels"])
    lcl_rotation = np.zeros((len(joints), frames, 3))
    root_translation = np.zeros((frames, 3))
    for f in range(frames):
        for j, joint in enumerate(joints):
            r, position = joint_motion(joint, values[f, columns[j][0]:columns[j][1]])
            local = rest[j].T @ r @ rest[j] @ post[j]
            lcl_rotation[j, f] = euler_xyz(local)
            if joint["parent"] is None:
                root_translation[f] = (position if position is not None else joint["offset"]) * scale
    for j in range(len(joints)):
        lcl_rotation[j] = unwrap(lcl_rotation[j])
        # The keys must say what they mean: each Euler triple gives back the matrix.
        for f in range(frames):
            r = from_euler_xyz(lcl_rotation[j, f])
            joint = joints[j]
            expected = rest[j].T @ joint_motion(joint, values[f, columns[j][0]:columns[j][1]])[0] @ rest[j] @ post[j]
            assert np.abs(r - expected).max() < 1e-9

    ids = Ids()
    models, objects, connections = [], [], []
    stop = int(round((frames - 1) / fps * KTIME_PER_SECOND))
    key_times = [int(round(f / fps * KTIME_PER_SECOND)) for f in range(frames)]

    def model(name, parent_id, pre, post_r, translation, rotation):
        attribute, node = ids(), ids()
        objects.append('\tNodeAttribute: %d, "NodeAttribute::", "LimbNode" {\n\t\tProperties70:  {\n'
                       '\t\t\tP: "Size", "double", "Number", "",100\n\t\t}\n\t\tTypeFlags: "Skeleton"\n\t}' % attribute)
        props = ['\t\t\tP: "RotationActive", "bool", "", "",1',
                 '\t\t\tP: "InheritType", "enum", "", "",1',
                 '\t\t\tP: "ScalingMax", "Vector3D", "Vector", "",0,0,0',
                 '\t\t\tP: "PreRotation", "Vector3D", "Vector", "",%s' % numbers(euler_xyz(pre)),
                 '\t\t\tP: "PostRotation", "Vector3D", "Vector", "",%s' % numbers(euler_xyz(post_r)),
                 '\t\t\tP: "Lcl Translation", "Lcl Translation", "", "A",%s' % numbers(translation),
                 '\t\t\tP: "Lcl Rotation", "Lcl Rotation", "", "A",%s' % numbers(rotation),
                 '\t\t\tP: "Lcl Scaling", "Lcl Scaling", "", "A",1,1,1']
        objects.append('\tModel: %d, "Model::%s", "LimbNode" {\n\t\tVersion: 232\n\t\tProperties70:  {\n%s\n\t\t}\n'
                       '\t\tShading: Y\n\t\tCulling: "CullingOff"\n\t}' % (node, name, "\n".join(props)))
        connections.append('\t;NodeAttribute::, Model::%s\n\tC: "OO",%d,%d' % (name, attribute, node))
        connections.append('\t;Model::%s, Model::parent\n\tC: "OO",%d,%d' % (name, node, parent_id))
        models.append(node)
        return node

    stack, layer = ids(), ids()
    objects.append('\tAnimationStack: %d, "AnimStack::mixamo.com", "" {\n\t\tProperties70:  {\n'
                   '\t\t\tP: "LocalStart", "KTime", "Time", "",0\n\t\t\tP: "LocalStop", "KTime", "Time", "",%d\n'
                   '\t\t\tP: "ReferenceStart", "KTime", "Time", "",0\n\t\t\tP: "ReferenceStop", "KTime", "Time", "",%d\n'
                   '\t\t}\n\t}' % (stack, stop, stop))
    objects.append('\tAnimationLayer: %d, "AnimLayer::BaseLayer", "" {\n\t}' % layer)
    connections.append('\tC: "OO",%d,%d' % (layer, stack))

    def curves(node, prop, short, tracks):
        curve_node = ids()
        defaults = "\n".join('\t\t\tP: "d|%s", "Number", "", "A",%.9g' % (a, t[0]) for a, t in zip("XYZ", tracks))
        objects.append('\tAnimationCurveNode: %d, "AnimCurveNode::%s", "" {\n\t\tProperties70:  {\n%s\n\t\t}\n\t}'
                       % (curve_node, short, defaults))
        connections.append('\tC: "OO",%d,%d' % (curve_node, layer))
        connections.append('\tC: "OP",%d,%d, "%s"' % (curve_node, node, prop))
        for axis, track in zip("XYZ", tracks):
            curve = ids()
            objects.append(
                '\tAnimationCurve: %d, "AnimCurve::", "" {\n\t\tDefault: %.9g\n\t\tKeyVer: 4009\n'
                '\t\tKeyTime: *%d {\n\t\t\ta: %s\n\t\t}\n\t\tKeyValueFloat: *%d {\n\t\t\ta: %s\n\t\t}\n'
                '\t\tKeyAttrFlags: *1 {\n\t\t\ta: 260\n\t\t}\n\t\tKeyAttrDataFloat: *4 {\n\t\t\ta: 0,0,0,0\n\t\t}\n'
                '\t\tKeyAttrRefCount: *1 {\n\t\t\ta: %d\n\t\t}\n\t}'
                % (curve, track[0], frames, ",".join(map(str, key_times)), frames, numbers(track), frames))
            connections.append('\tC: "OP",%d,%d, "d|%s"' % (curve, curve_node, axis))

    node_ids = []
    for j, joint in enumerate(joints):
        p = joint["parent"]
        parent_rest = rest[p] if p is not None else np.eye(3)
        parent_id = node_ids[p] if p is not None else 0
        translation = root_translation[0] if p is None else parent_rest.T @ joint["offset"] * scale
        # At rest the Lcl Rotation is the PostRotation (R_j = I).
        node = model("mixamorig:" + joint["name"], parent_id, parent_rest.T @ rest[j], post[j], translation,
                     euler_xyz(post[j]))
        node_ids.append(node)
        curves(node, "Lcl Rotation", "R", lcl_rotation[j].T)
        if p is None:
            curves(node, "Lcl Translation", "T", root_translation.T)
        if joint["end"] is not None:
            model("mixamorig:%s_End" % joint["name"], node, np.eye(3), np.eye(3), rest[j].T @ joint["end"] * scale, np.zeros(3))

    time_mode = {30: 6, 24: 11, 60: 3, 120: 1, 25: 10, 50: 4}.get(fps, 14)
    header = """; FBX 7.4.0 project file
; Mixamo-style fixture written by lab/scripts/make_mixamo_style_fbx.py
FBXHeaderExtension:  {
\tFBXHeaderVersion: 1003
\tFBXVersion: 7400
\tCreator: "sinmdm fixture script"
}
GlobalSettings:  {
\tVersion: 1000
\tProperties70:  {
\t\tP: "UpAxis", "int", "Integer", "",1
\t\tP: "UpAxisSign", "int", "Integer", "",1
\t\tP: "FrontAxis", "int", "Integer", "",2
\t\tP: "FrontAxisSign", "int", "Integer", "",1
\t\tP: "CoordAxis", "int", "Integer", "",0
\t\tP: "CoordAxisSign", "int", "Integer", "",1
\t\tP: "OriginalUpAxis", "int", "Integer", "",1
\t\tP: "OriginalUpAxisSign", "int", "Integer", "",1
\t\tP: "UnitScaleFactor", "double", "Number", "",1
\t\tP: "OriginalUnitScaleFactor", "double", "Number", "",1
\t\tP: "TimeMode", "enum", "", "",%d
\t\tP: "CustomFrameRate", "double", "Number", "",%d
\t\tP: "TimeSpanStart", "KTime", "Time", "",0
\t\tP: "TimeSpanStop", "KTime", "Time", "",%d
\t}
}
""" % (time_mode, fps, stop)
    with open(args.out, "w") as f:
        f.write(header)
        f.write("Objects:  {\n" + "\n".join(objects) + "\n}\n")
        f.write("Connections:  {\n" + "\n".join(connections) + "\n}\n")


main()

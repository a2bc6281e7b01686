"""Writes the retargeting fixtures of tests/data/gltf with Blender (PyPI's `bpy`), an independent
writer: the walk's skinned character (human_walk_cmu_131_01_skinned.glb) made into two other
characters, without its animation:

- `human_walk_rig_other_proportions.glb`: the same bone names, legs 1.2x (every leg bone: the
  hips stand 1.2x as high), arms 0.85x, spine, neck and head 1.1x longer, the arms lowered 40
  degrees (an A pose), every bone rolled;
- `human_walk_rig_unreal_names.glb`: the same rig with Unreal mannequin names (`pelvis`,
  `thigh_l`, `spine_01`), bones the mannequin lacks given names no convention knows.

Run: python -m venv v && v/bin/pip install 'bpy==4.5.*' && v/bin/python make_retarget_fixtures.py
"""

import math
import pathlib

import bpy
import mathutils

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "tests" / "data" / "gltf"
SOURCE = FIXTURES / "human_walk_cmu_131_01_skinned.glb"

PELVIS = ("HipJoint", "Hip")
THIGH = ("Knee",)
SHIN = ("Ankle", "Toe")
ARM = ("Shoulder", "Elbow", "Wrist", "hand", "Fingers", "Thumb")
SIDES = {"Left": "l", "Right": "r", "L": "l", "R": "r", "l": "l", "r": "r"}

UNREAL = {
    "Hips": "pelvis",
    "lowerback": "spine_01",
    "Chest": "spine_02",
    "Chest2": "spine_03",
    "lowerneck": "neck_01",
    "Neck": "neck_02",
    "Head": "head",
}
for long, s in (("Left", "l"), ("Right", "r")):
    short = long[0]
    UNREAL.update({
        f"{short}HipJoint": f"hip_socket_{s}",
        f"{long}Hip": f"thigh_{s}",
        f"{long}Knee": f"calf_{s}",
        f"{long}Ankle": f"foot_{s}",
        f"{long}Toe": f"ball_{s}",
        f"{long}Collar": f"clavicle_{s}",
        f"{long}Shoulder": f"upperarm_{s}",
        f"{long}Elbow": f"lowerarm_{s}",
        f"{long}Wrist": f"hand_{s}",
        f"{s}hand": f"palm_{s}",
        f"{short}Fingers": f"index_01_{s}",
        f"{short}Thumb": f"thumb_01_{s}",
    })


def group(name):
    base = name.removesuffix("_end")
    # A bone's offset from its parent is the parent's bone: the knee's offset is the thigh.
    for name, parts in (("pelvis", PELVIS), ("thigh", THIGH), ("shin", SHIN)):
        if any(base.endswith(part) for part in parts):
            return name
    if any(base.endswith(part) for part in ARM) and "Collar" not in base:
        return "arm"
    return "body"


FACTOR = {"pelvis": 1.2, "thigh": 1.2, "shin": 1.2, "arm": 0.85, "body": 1.1}


def load():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(SOURCE))
    armature = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    for o in bpy.data.objects:
        o.animation_data_clear()
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)
    return armature


def depth(bone):
    d = 0
    while bone.parent:
        d, bone = d + 1, bone.parent
    return d


def reshape(armature):
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    bones = armature.data.edit_bones
    old = {b.name: (b.head.copy(), b.tail.copy(), b.parent.name if b.parent else None) for b in bones}
    for b in bones:
        b.use_connect = False
    order = sorted(bones, key=depth)
    head = {}
    for b in order:
        h, _, p = old[b.name]
        head[b.name] = h.copy() if p is None else head[p] + (h - old[p][0]) * FACTOR[group(b.name)]
    # The arms lowered into an A pose about each upper arm's head.
    turned = {}
    for b in order:
        if b.name.endswith("Shoulder") and "Collar" not in b.name:
            pivot = head[b.name]
            outward = old[b.name][1] - old[b.name][0]
            angle = math.radians(40.0) * (1.0 if outward.x > 0 else -1.0)
            turn = mathutils.Matrix.Rotation(angle, 3, "Y")
            below = [c for c in order if c == b or b in c.parent_recursive]
            for c in below:
                turned[c.name] = (pivot, turn)
    for i, b in enumerate(order):
        h, t, _ = old[b.name]
        new_head = head[b.name]
        new_tail = new_head + (t - h) * FACTOR[group(b.name)]
        if b.name in turned:
            pivot, turn = turned[b.name]
            new_head = pivot + turn @ (new_head - pivot)
            new_tail = pivot + turn @ (new_tail - pivot)
        b.head, b.tail = new_head, new_tail
        b.roll += math.radians(20.0 + 15.0 * (i % 3))
    bpy.ops.object.mode_set(mode="OBJECT")


def export(path):
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_animations=False)
    print("wrote", path)


armature = load()
reshape(armature)
export(FIXTURES / "human_walk_rig_other_proportions.glb")

armature = load()
reshape(armature)
for bone in armature.data.bones:
    base = bone.name.removesuffix("_end")
    end = "_end" if bone.name.endswith("_end") else ""
    if base in UNREAL:
        bone.name = UNREAL[base] + end
export(FIXTURES / "human_walk_rig_unreal_names.glb")

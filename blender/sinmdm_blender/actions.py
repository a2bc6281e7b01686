"""Pose-bone keys of a generated clip written into actions of the same armature, fast
(`foreach_set`), in each bone's own rotation mode, and pushed to NLA tracks for auditioning."""

import bpy
import numpy as np
from mathutils import Matrix

LINEAR = 1  # the enum value of the keyframe interpolation 'LINEAR' (foreach_set takes integers)


def _channels(rig, bone_index, basis):
    """{(data path, index): values F} of one bone's basis matrices (F x 4 x 4): its rotation in
    the pose bone's rotation mode, and its location for the root (the only bone that travels)."""
    pb = rig.obj.pose.bones[rig.names[bone_index]]
    path = f'pose.bones["{bpy.utils.escape_identifier(pb.name)}"]'
    out = {}
    mode = pb.rotation_mode
    if mode in ("QUATERNION", "AXIS_ANGLE"):
        quats = np.array([Matrix(m[:3, :3].tolist()).to_quaternion() for m in basis])
        # One hemisphere from frame to frame, so that keys interpolate the short way.
        for f in range(1, len(quats)):
            if np.dot(quats[f], quats[f - 1]) < 0.0:
                quats[f] = -quats[f]
        if mode == "QUATERNION":
            for i in range(4):
                out[(path + ".rotation_quaternion", i)] = quats[:, i]
        else:
            from mathutils import Quaternion

            axis_angles = [Quaternion(q).to_axis_angle() for q in quats]
            values = np.array([[a, *axis] for axis, a in axis_angles])
            for i in range(4):
                out[(path + ".rotation_axis_angle", i)] = values[:, i]
    else:
        eulers, previous = [], None
        for m in basis:
            # Each angle nearest the previous frame's, so keys do not jump by whole turns.
            previous = Matrix(m[:3, :3].tolist()).to_euler(mode, *([previous] if previous else []))
            eulers.append(tuple(previous))
        eulers = np.array(eulers)
        for i in range(3):
            out[(path + ".rotation_euler", i)] = eulers[:, i]
    if rig.parents[bone_index] < 0:
        for i in range(3):
            out[(path + ".location", i)] = basis[:, i, 3]
    return out, pb.name


def fcurves_of(action, obj):
    """The F-curve collection of `action` for `obj`: the slot's channel bag where actions have
    slots (Blender 4.4+), else the action's own."""
    try:
        from bpy_extras import anim_utils

        ensure = anim_utils.action_ensure_channelbag_for_slot
    except (ImportError, AttributeError):
        return action.fcurves
    slot = action.slots[0] if len(action.slots) else action.slots.new(id_type="OBJECT", name=obj.name)
    return ensure(action, slot).fcurves


def write_action(rig, name, bones, bases, frames):
    """A new action named `name` with keys at `frames` (F, scene frames, may be fractional) for
    every bone in `bones` (indices into the rig) from their basis matrices (F x K x 4 x 4)."""
    action = bpy.data.actions.new(name)
    action.use_fake_user = True
    curves = fcurves_of(action, rig.obj)
    for k, j in enumerate(bones):
        channels, bone_name = _channels(rig, j, bases[:, k])
        for (path, index), values in channels.items():
            fc = curves.new(path, index=index, action_group=bone_name)
            _set_keys(fc, frames, values)
    return action


def _set_keys(fc, frames, values):
    fc.keyframe_points.add(len(frames))
    co = np.empty(2 * len(frames), dtype=np.float32)
    co[0::2] = frames
    co[1::2] = values
    fc.keyframe_points.foreach_set("co", co)
    fc.keyframe_points.foreach_set("interpolation", np.full(len(frames), LINEAR, dtype=np.int32))
    fc.update()


GAP_MARGIN = 0.5
"""Keys within half a frame of the gap's border frames belong to the border: imported keys sit a
few 1e-5 frames off whole frames, and Blender merges a key inserted within 0.01 of another."""


def replace_keys_between(rig, action, bones, bases, frames, after, before):
    """Writes the generated keys strictly between scene frames `after` and `before` into
    `action`: the keys there on the channels the model drives are replaced, every other key
    is left exactly as it was (see GAP_MARGIN for the border)."""
    curves = fcurves_of(action, rig.obj)
    after, before = after + GAP_MARGIN, before - GAP_MARGIN
    inside = (frames > after) & (frames < before)
    for k, j in enumerate(bones):
        channels, bone_name = _channels(rig, j, bases[:, k])
        for (path, index), values in channels.items():
            fc = curves.find(path, index=index) or curves.new(path, index=index, action_group=bone_name)
            for kp in reversed(list(fc.keyframe_points)):
                if after < kp.co[0] < before:
                    fc.keyframe_points.remove(kp, fast=True)
            for frame, value in zip(frames[inside], values[inside]):
                kp = fc.keyframe_points.insert(float(frame), float(value), options={"FAST"})
                kp.interpolation = "LINEAR"
                kp.handle_left_type = kp.handle_right_type = "FREE"
                kp.handle_left = kp.handle_right = kp.co
            # No fc.update(): it would recompute the kept keys' automatic handles.


def push_to_nla(obj, action, start):
    """Puts `action` on a new NLA track of `obj` at scene frame `start`, named after it; the
    active action is untouched (star a track to audition it)."""
    anim = obj.animation_data_create()
    track = anim.nla_tracks.new()
    track.name = action.name
    strip = track.strips.new(action.name, int(round(start)), action)
    strip.name = action.name
    return track

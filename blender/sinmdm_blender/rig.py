"""An armature's action as a world-space BVH clip, and a BVH clip back as pose-bone keys of the
same armature.

The clip is sampled from the pose bones (not through an exporter): what the viewport shows,
constraints and drivers included, in world units, whatever the bones' rolls or the object's
transform. Each joint's rest frame is the world's axes, so rolls never reach the model, and the
way back is the exact inverse: a bone's basis is solved from its world rotation and its rest.
"""

import re

import numpy as np

from . import bvh_text


class RigError(Exception):
    """A rig or clip the add-on cannot use, with what to change."""


def joint_name(bone_name):
    """The BVH joint name of a bone: whitespace becomes `_` (BVH names are single tokens)."""
    return re.sub(r"\s", "_", bone_name)


class Rig:
    """The bones the model learns: the largest bone tree of the armature, depth first."""

    def __init__(self, obj):
        if obj is None or obj.type != "ARMATURE":
            raise RigError("select an armature (the active object is not one)")
        self.obj = obj
        roots = [b for b in obj.data.bones if b.parent is None]
        if not roots:
            raise RigError(f"armature '{obj.name}' has no bones")
        root = max(roots, key=lambda b: len(b.children_recursive))
        self.bones = []

        def visit(bone):
            self.bones.append(bone)
            for child in sorted(bone.children, key=lambda c: c.name):
                visit(child)

        visit(root)
        self.names = [b.name for b in self.bones]
        self.joints = [joint_name(n) for n in self.names]
        if len(set(self.joints)) != len(self.joints):
            raise RigError("two bones differ only by spaces; rename one so the model can tell them apart")
        index = {b.name: i for i, b in enumerate(self.bones)}
        self.parents = [index[b.parent.name] if b.parent else -1 for b in self.bones]
        self.rest = np.array([np.array(b.matrix_local) for b in self.bones])  # armature space
        world = np.array(obj.matrix_world)
        scales = np.linalg.norm(world[:3, :3], axis=0)
        if np.ptp(scales) > 1e-4 * scales.max():
            raise RigError(
                f"'{obj.name}' has a non-uniform scale {tuple(round(s, 4) for s in scales)}: "
                "apply it (Ctrl+A, Scale) so bone lengths are the same in every direction"
            )
        self.world = world
        self.scale = float(scales.mean())
        self.world_rotation = world[:3, :3] / self.scale

    def _world_points(self, points):
        return points @ self.world[:3, :3].T + self.world[:3, 3]

    def skeleton(self):
        """The world-aligned rest skeleton: offsets between world rest heads."""
        heads = self._world_points(self.rest[:, :3, 3])
        offsets = np.array([heads[j] - heads[p] if p >= 0 else heads[j] for j, p in enumerate(self.parents)])
        tails = self._world_points(np.array([np.array(b.tail_local) for b in self.bones]))
        ends = {j: tuple(tails[j] - heads[j]) for j in range(len(self.bones)) if not self.bones[j].children}
        return bvh_text.Skeleton(self.joints, self.parents, offsets, ends, [[] for _ in self.joints])

    def sample(self, scene, action, first, last):
        """Armature-space pose matrices (F x J x 4 x 4) of `action` alone, frames first..last."""
        anim = self.obj.animation_data_create()
        saved = (anim.action, anim.use_nla, scene.frame_current, scene.frame_subframe)
        slot = getattr(anim, "action_slot", None)
        try:
            assign(anim, action)
            anim.use_nla = False
            pose = self.obj.pose.bones
            mats = []
            for frame in range(first, last + 1):
                scene.frame_set(frame)
                mats.append([np.array(pose[n].matrix) for n in self.names])
        finally:
            anim.action = saved[0]
            if slot is not None and saved[0] is not None:
                anim.action_slot = slot
            anim.use_nla = saved[1]
            scene.frame_set(saved[2], subframe=saved[3])
        return np.array(mats)

    def to_bvh(self, pose, fps):
        """BVH text of sampled poses (F x J x 4 x 4): world positions, rotations from rest."""
        rest_rot = _orthonormal(self.rest[:, :3, :3])
        pose_rot = _orthonormal(pose[:, :, :3, :3])
        w = self.world_rotation
        delta = w @ pose_rot @ np.swapaxes(rest_rot, -1, -2) @ w.T  # F x J x 3 x 3, world
        local = delta.copy()
        for j, p in enumerate(self.parents):
            if p >= 0:
                local[:, j] = np.swapaxes(delta[:, p], -1, -2) @ delta[:, j]
        root = self._world_points(pose[:, 0, :3, 3])
        return bvh_text.write(self.skeleton(), root, local, fps)

    def bases_from_bvh(self, text):
        """(bone indices the clip drives, basis matrices F x K x 4 x 4, frame time) of a BVH text
        written for this rig; bones the clip lacks are left out, joints the rig lacks ignored."""
        skeleton, values, frame_time = bvh_text.read(text)
        delta, positions = bvh_text.forward_kinematics(skeleton, values)
        by_joint = {n: i for i, n in enumerate(skeleton.names)}
        driven = [j for j, name in enumerate(self.joints) if name in by_joint]
        if 0 not in driven:
            raise RigError("the model's skeleton does not match this armature's bones (learn on this rig first)")
        frames = values.shape[0]
        inverse_world = np.linalg.inv(self.world)
        w = self.world_rotation
        pose = {}
        for j in driven:
            k = by_joint[self.joints[j]]
            m = np.zeros((frames, 4, 4))
            m[:, :3, :3] = w.T @ delta[:, k] @ w @ _orthonormal(self.rest[j, :3, :3])
            m[:, :3, 3] = positions[:, k] @ inverse_world[:3, :3].T + inverse_world[:3, 3]
            m[:, 3, 3] = 1.0
            pose[j] = m
        bases = []
        for j in driven:
            p = self.parents[j]
            if p < 0:
                basis = np.linalg.inv(self.rest[j]) @ pose[j]
            elif p in pose:
                rest_in_parent = np.linalg.inv(self.rest[p]) @ self.rest[j]
                basis = np.linalg.inv(rest_in_parent) @ np.linalg.inv(pose[p]) @ pose[j]
            else:
                continue
            bases.append((j, basis))
        return [j for j, _ in bases], np.stack([b for _, b in bases], axis=1), frame_time


def assign(anim, action):
    """Makes `action` the active one; where actions have slots (Blender 4.4+) its first slot is
    taken when none was picked, as happens for an action an NLA strip already uses."""
    anim.action = action
    if getattr(anim, "action_slot", False) is None and len(action.slots):
        anim.action_slot = action.slots[0]


def _orthonormal(m):
    """The rotation part of matrices that may carry a scale (columns normalised)."""
    return m / np.linalg.norm(m, axis=-2, keepdims=True)

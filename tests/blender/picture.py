"""One frame of several actions of the same armature, rendered side by side with Workbench
(headless), for the add-on's README picture. The rig gets a box per bone, skinned to it, so
that an armature alone (which renders nothing) shows its pose."""

import bpy
import numpy as np
from mathutils import Vector


def skin_boxes(arm, width):
    """A mesh of one box per bone, each box weighted fully to its bone (an Armature modifier)."""
    verts, faces, groups = [], [], []
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    for bone in arm.data.bones:
        m = bone.matrix_local
        x, z = Vector(m.col[0][:3]), Vector(m.col[2][:3])
        head, tail = bone.head_local, bone.tail_local
        base = len(verts)
        for end in (head, tail):
            for sx in (-1, 1):
                for sz in (-1, 1):
                    verts.append(end + sx * width * x + sz * width * z)
        faces += [tuple(base + i for i in q) for q in quads]
        groups.append((bone.name, list(range(base, base + 8))))
    mesh = bpy.data.meshes.new("bone_boxes")
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    obj = bpy.data.objects.new("bone_boxes", mesh)
    bpy.context.scene.collection.objects.link(obj)
    for name, indices in groups:
        obj.vertex_groups.new(name=name).add(indices, 1.0, "REPLACE")
    obj.parent = arm
    obj.modifiers.new("armature", "ARMATURE").object = arm
    return obj


def _heads(arm):
    return np.array([list(arm.matrix_world @ pb.head) for pb in arm.pose.bones])


def widest_frame(arm, action):
    """The frame of `action` whose pose spreads widest over the ground (mid-stride for a walk)."""
    scene = bpy.context.scene
    first, last = (int(round(f)) for f in action.frame_range)
    best, frame = -1.0, first
    for f in range(first, last + 1):
        scene.frame_set(f)
        spread = float(np.ptp(_heads(arm)[:, :2], axis=0).max())
        if spread > best:
            best, frame = spread, f
    return frame


def render_side_by_side(arm, actions, path, size=360):
    """Renders each action of `arm` at its widest pose and writes them side by side to `path`."""
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "SINGLE"
    scene.display.shading.single_color = (0.85, 0.55, 0.3)
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.film_transparent = False
    world = bpy.data.worlds.new("plain") if scene.world is None else scene.world
    scene.world = world
    world.color = (0.93, 0.93, 0.93)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.data.type = "ORTHO"
    anim = arm.animation_data
    anim.use_nla = False
    tiles = []
    for i, action in enumerate(actions):
        anim.action = action
        if anim.action_slot is None:
            anim.action_slot = action.slots[0]
        scene.frame_set(widest_frame(arm, action))
        heads = _heads(arm)
        low, high = heads.min(axis=0), heads.max(axis=0)
        center = Vector(((low + high) / 2).tolist())
        extent = float(np.max(high - low))
        direction = Vector((1.0, -1.4, 0.45)).normalized()
        camera.location = center + direction * extent * 4
        camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
        camera.data.ortho_scale = extent * 1.35
        camera.data.clip_end = extent * 10
        tile = f"{path}.{i}.png"
        scene.render.filepath = tile
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(tile)
        tiles.append(np.array(image.pixels[:]).reshape(size, size, 4))
    strip = np.concatenate(tiles, axis=1)
    out = bpy.data.images.new("side_by_side", strip.shape[1], strip.shape[0], alpha=True)
    out.pixels = strip.ravel().tolist()
    out.filepath_raw = path
    out.file_format = "PNG"
    out.save()

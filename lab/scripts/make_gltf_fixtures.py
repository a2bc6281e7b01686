"""Makes the glTF fixtures of tests/data/gltf with Blender, an independent writer: each source
BVH (cut to 2 s, at most 30 fps) is imported, then exported as GLB with the armature only and
with a small mesh skinned to it (both sampled every frame, LINEAR), and unsampled as a STEP and
a CUBICSPLINE variant. glTF keeps no bone tails, so a still bone is added at every leaf bone's
tail to carry the BVH's End Site. With --fbx it also writes binary FBX files (armature only and
skinned, the first second, Blender's own leaf bones), which tests/data/fbx keeps gzipped
(`gzip -9n`). The Mixamo-style FBX comes from make_mixamo_style_fbx.py.

Blender 3.4's unsampled export does not reproduce the BVH's pose (three.js and our reader agree
on what the files hold, and both differ from the BVH), so the STEP and CUBICSPLINE files are
checked against three.js, the sampled ones against the BVH.

Run on a machine with Debian's blender and python3-numpy (CI needs neither; the fixtures are
committed):
    blender -b --factory-startup --python lab/scripts/make_gltf_fixtures.py -- OUT_DIR [--fbx] CLIP.bvh...
"""

import builtins
import os
import sys

import bpy

# Debian's Blender 3.4 runs Python 3.11, where open() no longer takes the 'U' mode its BVH
# importer still asks for: drop the letter.
_open = builtins.open


def _open_without_u(file, mode="r", *args, **kwargs):
    return _open(file, mode.replace("U", ""), *args, **kwargs)


builtins.open = _open_without_u

SECONDS = 2.0
MAX_FPS = 30.0


def cut_bvh(path, out_path):
    """The BVH at `path` cut to its first SECONDS and thinned to at most MAX_FPS (every k-th
    frame), written to `out_path`; returns its frames."""
    text = open(path).read()
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frame_time = float(lines[1].split(":")[1])
    step = max(1, int(round(1.0 / (frame_time * MAX_FPS))))
    frames = [l for l in lines[2:] if l.strip()][::step]
    frame_time *= step
    keep = min(len(frames), int(round(SECONDS / frame_time)) + 1)
    with open(out_path, "w") as f:
        f.write(head + "MOTION\nFrames: %d\nFrame Time: %.7f\n" % (keep, frame_time))
        f.write("\n".join(frames[:keep]) + "\n")
    return keep


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def import_bvh(path):
    bpy.ops.import_anim.bvh(filepath=path, axis_forward="-Z", axis_up="Y", update_scene_fps=True,
                            update_scene_duration=True, rotate_mode="NATIVE")
    armature = bpy.context.selected_objects[0]
    return armature


def add_skinned_mesh(armature):
    """A small cube bound entirely to the root bone, with an Armature modifier."""
    root = armature.data.bones[0]
    bpy.ops.mesh.primitive_cube_add(size=0.1 * max(armature.dimensions), location=armature.matrix_world @ root.head_local)
    cube = bpy.context.active_object
    group = cube.vertex_groups.new(name=root.name)
    group.add([v.index for v in cube.data.vertices], 1.0, "REPLACE")
    modifier = cube.modifiers.new("Armature", "ARMATURE")
    modifier.object = armature
    cube.parent = armature
    return cube


def set_interpolation(armature, kind):
    for fcurve in armature.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = kind


def export_gltf(path, sampling=True):
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_animations=True,
                              export_force_sampling=sampling, export_def_bones=False,
                              export_yup=True, export_skins=True)


def compress_fbx_arrays_fully():
    """Blender's FBX writer compresses arrays with zlib at level 1; level 9 gives the same
    arrays in a smaller file."""
    import zlib

    import io_scene_fbx.encode_bin as encode_bin

    class Zlib9:
        @staticmethod
        def compress(data, level=9):
            return zlib.compress(data, 9)

    encode_bin.zlib = Zlib9


def export_fbx(path, **extra):
    bpy.ops.export_scene.fbx(filepath=path, bake_anim=True, bake_anim_simplify_factor=0.0,
                             bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False,
                             add_leaf_bones=extra.pop("leaf", False), **extra)


FBX_SECONDS = 1.0


def export_fbx_cut(path, **extra):
    """FBX files hold every bone's nine curves with their own key times, so the FBX fixtures
    keep the first FBX_SECONDS of the cut clip to stay small. Leaf bones (Blender's `_end`
    bones) carry the End Sites."""
    scene = bpy.context.scene
    end = scene.frame_end
    scene.frame_end = scene.frame_start + int(round(FBX_SECONDS * scene.render.fps))
    export_fbx(path, leaf=True, **extra)
    scene.frame_end = end


def add_end_bones(armature):
    """A still bone at the tail of every leaf bone, so the GLB keeps the BVH's End Sites (glTF
    has no bone tails; a reader folds a still leaf bone back into an End Site)."""
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    bones = armature.data.edit_bones
    for bone in [b for b in bones if not b.children]:
        end = bones.new(bone.name + "_end")
        end.head = bone.tail
        end.tail = bone.tail + (bone.tail - bone.head) * 0.25
        end.roll = bone.roll
        end.parent = bone
        end.use_connect = True
    bpy.ops.object.mode_set(mode="OBJECT")


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    fbx = "--fbx" in argv
    argv = [a for a in argv if a != "--fbx"]
    out, clips = argv[0], argv[1:]
    os.makedirs(out, exist_ok=True)
    compress_fbx_arrays_fully()
    for clip in clips:
        name = os.path.splitext(os.path.basename(clip))[0]
        cut = os.path.join(out, name + "_2s.bvh")
        cut_bvh(clip, cut)
        reset()
        armature = import_bvh(cut)
        if fbx:
            export_fbx_cut(os.path.join(out, name + "_armature.fbx"), object_types={"ARMATURE"})
        add_end_bones(armature)
        export_gltf(os.path.join(out, name + "_armature.glb"))
        set_interpolation(armature, "CONSTANT")
        export_gltf(os.path.join(out, name + "_step.glb"), sampling=False)
        set_interpolation(armature, "BEZIER")
        export_gltf(os.path.join(out, name + "_cubic.glb"), sampling=False)

        reset()
        armature = import_bvh(cut)
        add_skinned_mesh(armature)
        if fbx:
            export_fbx_cut(os.path.join(out, name + "_skinned.fbx"))
        add_end_bones(armature)
        export_gltf(os.path.join(out, name + "_skinned.glb"))


main()

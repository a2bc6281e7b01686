"""A Blender session that uses the add-on as an animator would, run headless by
`tests/python/test_blender_addon.py` with PyPI's `bpy` (Blender 4.5 as a Python module).

It installs the packaged zip, enables the add-on, imports a shipped rig, presses the panel's
buttons through their operators (Learn, Generate, In-between, Start Learn + Cancel, Learn again)
and writes what it saw to OUT/report.json and OUT/heads.npz (every generated key's bone heads in
world space), for the test to compare with `sinmdm generate` read by an independent BVH reader.

Run: python addon_session.py ROOT ADDON.zip RIG(glb|fbx|bvh) OUT
"""

import json
import os
import pathlib
import sys
import time

import bpy  # first: it puts Blender's own modules on the path
import addon_utils  # noqa: E402
import numpy as np

ROOT, ZIP, RIG, OUT = (pathlib.Path(a) for a in sys.argv[1:5])
RIG = RIG.name
OUT.mkdir(parents=True, exist_ok=True)
report = {"rig": RIG}


def tiny_config(steps, every):
    text = (ROOT / "configs" / "tiny.yaml").read_text()
    assert "steps: 300" in text and "checkpoint_every: 100" in text
    path = OUT / f"tiny_{steps}.yaml"
    path.write_text(text.replace("steps: 300", f"steps: {steps}").replace("checkpoint_every: 100", f"checkpoint_every: {every}"))
    return str(path)


def enable():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.preferences.addon_install(filepath=str(ZIP), overwrite=True)
    addon_utils.enable("sinmdm_blender", default_set=True)
    prefs = bpy.context.preferences.addons["sinmdm_blender"].preferences
    prefs.binaries = str(OUT / "no-such-folder")
    report["status_without_programs"] = prefs.status
    prefs.binaries = str(ROOT / "target" / "release")
    report["status"] = prefs.status
    prefs.work_folder = str(OUT / "runs")


def import_rig():
    """The rig, on an Empty parent that scales and turns it (world space is not the armature's)."""
    if RIG == "glb":
        bpy.ops.import_scene.gltf(filepath=str(ROOT / "tests/data/gltf/human_walk_cmu_131_01_skinned.glb"))
    elif RIG == "bvh":  # Blender's BVH importer: Euler bones in the file's channel order
        bpy.ops.import_anim.bvh(filepath=str(ROOT / "tests/data/gltf/human_walk_cmu_131_01_2s.bvh"), rotate_mode="NATIVE")
    else:
        import gzip

        fbx = OUT / "walk.fbx"
        fbx.write_bytes(gzip.decompress((ROOT / "tests/data/fbx/human_walk_cmu_131_01_skinned.fbx.gz").read_bytes()))
        bpy.ops.import_scene.fbx(filepath=str(fbx))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    parent = bpy.data.objects.new("Holder", None)
    bpy.context.scene.collection.objects.link(parent)
    parent.scale = (1.5, 1.5, 1.5)
    parent.rotation_euler = (0.0, 0.0, 0.6)
    arm.parent = parent
    bpy.context.view_layer.update()
    bpy.context.view_layer.objects.active = arm
    arm.select_set(True)
    return arm


def heads_of(arm, action, names):
    """World heads (F x J x 3) of `names` at every key time of `action`, the action alone."""
    anim = arm.animation_data
    saved = anim.action
    anim.action = action
    if anim.action_slot is None:  # an action an NLA strip uses gets no slot by itself
        anim.action_slot = action.slots[0]
    anim.use_nla = False
    scene = bpy.context.scene
    curve = next(fc for fc in action.fcurves if fc.data_path.endswith("location"))
    times = [kp.co[0] for kp in curve.keyframe_points]
    out = []
    for t in times:
        scene.frame_set(int(np.floor(t)), subframe=float(t - np.floor(t)))
        world = arm.matrix_world
        out.append([list(world @ arm.pose.bones[n].head) for n in names])
    anim.action = saved
    anim.use_nla = True
    return np.array(out), times


def keys_of(action):
    """{(data path, index): [(frame, value, left handle, right handle)]} of every F-curve."""
    return {
        (fc.data_path, fc.array_index): [
            (kp.co[0], kp.co[1], tuple(kp.handle_left), tuple(kp.handle_right)) for kp in fc.keyframe_points
        ]
        for fc in action.fcurves
    }


def made_by(operator):
    before = set(bpy.data.actions)
    assert operator() == {"FINISHED"}
    (action,) = [a for a in bpy.data.actions if a not in before]
    return action


def root_path(arm, action, root):
    """The root bone's world head at the action's first and last key."""
    heads, _ = heads_of(arm, action, [root])
    return heads[0, 0], heads[-1, 0]


def other_tasks(arm, source, settings, names):
    """Expand, Steer along a curve and Dance to the sound strip, each once: what they made."""
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    out = {}
    settings.count, settings.prefix, settings.suffix = 1, 1.0, 0.5
    expanded = made_by(bpy.ops.sinmdm.expand)
    out["expand"] = {"source": list(source.frame_range), "made": list(expanded.frame_range), "fps": fps}

    scene.sequence_editor_create()
    strips = getattr(scene.sequence_editor, "strips", None) or scene.sequence_editor.sequences
    music = ROOT / "tests/data/audio/loop_amen_full.wav"
    strip = strips.new_sound("music", str(music), 1, 20)
    try:
        danced = made_by(bpy.ops.sinmdm.dance)
        out["dance"] = {"strip": [strip.frame_start, strip.frame_final_duration], "made": list(danced.frame_range)}
    except RuntimeError as e:  # a clip too short for a dance beat: the error says so
        out["dance_refused"] = str(e)
    # A bent curve from the root, about 2.3 heights long, walked in 3 s.
    start, _ = root_path(arm, source, names[0])
    height = float(np.ptp(heads_of(arm, source, names)[0][0, :, 2]))
    curve = bpy.data.curves.new("path", "CURVE")
    curve.dimensions = "3D"
    spline = curve.splines.new("POLY")
    points = [start + np.array(d) * height for d in ((0, 0, 0), (0.3, -1.0, 0), (1.0, -2.0, 0))]
    spline.points.add(len(points) - 1)
    for p, xyz in zip(spline.points, points):
        p.co = (*xyz, 1.0)
    curve_obj = bpy.data.objects.new("path", curve)
    scene.collection.objects.link(curve_obj)
    settings.curve, settings.seconds = curve_obj, 3.0
    if RIG != "glb":  # learned with the world layout: Steer says what it needs
        try:
            bpy.ops.sinmdm.steer()
        except RuntimeError as e:
            out["steer_refused"] = str(e)
        return out
    steered = made_by(bpy.ops.sinmdm.steer)
    first, last = root_path(arm, steered, names[0])
    out["steer"] = {
        "seconds": (steered.frame_range[1] - steered.frame_range[0]) / fps,
        "root_start": list(map(float, first)),
        "root_end": list(map(float, last)),
        "curve_start": list(map(float, points[0])),
        "curve_end": list(map(float, points[-1])),
        "height": height,
    }

    return out


def inbetween_keeps(source, after, before):
    """Presses In-between and compares the new action's keys outside (after, before) with the
    source's: counts, and whether every one (frame, value, handles) is the same."""
    made = made_by(bpy.ops.sinmdm.inbetween)
    a, b = after + 0.5, before - 0.5  # the add-on's GAP_MARGIN
    src_keys, new_keys = keys_of(source), keys_of(made)
    kept_equal, kept_count, inside_changed = True, 0, 0
    for key, points in src_keys.items():
        outside = [p for p in points if not a < p[0] < b]
        got = [p for p in new_keys.get(key, []) if not a < p[0] < b]
        kept_count += len(outside)
        if outside != got and "first_difference" not in report:
            report["first_difference"] = [key, [p[:2] for p in outside[:3]], [p[:2] for p in got[:3]]]
        kept_equal &= outside == got
        inside_changed += sum(1 for p in new_keys.get(key, []) if a < p[0] < b and p not in points)
    return {"kept_keys": kept_count, "kept_equal": kept_equal, "new_inside": inside_changed}


def main():
    enable()
    arm = import_rig()
    pointer = arm.as_pointer()
    source = arm.animation_data.action
    settings = bpy.context.scene.sinmdm
    if RIG == "glb":
        # The default network, trained for the one minute the panel's Minutes asks: enough for
        # the picture's samples to move.
        settings.config, settings.minutes, settings.root_layout = "", 1.0, "heading"
    else:
        settings.config = tiny_config(300, 100)
    assert bpy.ops.sinmdm.learn() == {"FINISHED"}
    report["model"] = bpy.path.abspath(arm["sinmdm_model"])

    # Rotation modes the user chose are kept: a few bones in Euler and axis-angle.
    modes = ["XYZ", "QUATERNION", "AXIS_ANGLE", "YZX"]
    for i, pb in enumerate(list(arm.pose.bones)[1:9]):
        pb.rotation_mode = modes[i % len(modes)]
    report["modes"] = {pb.name: pb.rotation_mode for pb in arm.pose.bones}

    settings.count, settings.seconds, settings.seed, settings.steps = 2, 2.0, 7, 20
    before = set(bpy.data.actions)
    assert bpy.ops.sinmdm.generate() == {"FINISHED"}
    made = sorted((a for a in bpy.data.actions if a not in before), key=lambda a: a.name)
    report["generated"] = [a.name for a in made]
    report["request"] = {"count": 2, "seconds": 2.0, "seed": 7, "steps": 20}
    report["same_object"] = arm.as_pointer() == pointer and bpy.data.objects.get(arm.name) == arm
    report["armatures"] = sum(o.type == "ARMATURE" for o in bpy.data.objects)
    report["nla_tracks"] = [t.name for t in arm.animation_data.nla_tracks]
    report["active_action"] = arm.animation_data.action.name
    names = [b.name for b in arm.data.bones]
    report["bones"] = names
    heads = {}
    for i, action in enumerate(made):
        heads[f"heads_{i}"], times = heads_of(arm, action, names)
        report[f"times_{i}"] = times
        report[f"curves_{i}"] = sorted({fc.data_path.split(".")[-1] for fc in action.fcurves})
    np.savez(OUT / "heads.npz", **heads)

    # In-between: the keys outside the gap stay exactly as they were; the gap is the preview
    # range, then two markers.
    scene = bpy.context.scene
    first, last = (int(round(f)) for f in source.frame_range)
    settings.count = 1
    scene.use_preview_range = True
    scene.frame_preview_start, scene.frame_preview_end = first + 8, last - 8
    report["inbetween"] = inbetween_keeps(source, first + 8, last - 8)
    scene.use_preview_range = False
    scene.timeline_markers.new("from", frame=first + 5)
    scene.timeline_markers.new("to", frame=last - 12)
    report["inbetween_markers"] = inbetween_keeps(source, first + 5, last - 12)

    report["more"] = other_tasks(arm, source, settings, names)

    # Cancel during Learn leaves a run that Learn resumes.
    from sinmdm_blender import jobs

    settings.use_scene_range = True
    scene.frame_start, scene.frame_end = first, last - 2
    settings.config, settings.minutes = tiny_config(400, 20), 0.0
    del arm["sinmdm_run"]
    assert bpy.ops.sinmdm.start_learn() == {"FINISHED"}
    job = jobs.current()
    run = pathlib.Path(job.argv[job.argv.index("--out") + 1])
    deadline = time.time() + 300
    while time.time() < deadline and not any(run.glob("**/step-*")) and job.running():
        time.sleep(0.2)
    assert bpy.ops.sinmdm.cancel() == {"FINISHED"}
    report["cancel"] = {
        "exit": job.process.returncode,
        "checkpoints": sorted(p.name for p in run.glob("**/step-*")),
        "model_after_cancel": (run.parent / "model.onnx").exists(),
        "message": scene.sinmdm.message,
    }
    # Learn again the way the panel runs it: started, then the timer until the job is applied.
    from sinmdm_blender import operators

    assert bpy.ops.sinmdm.start_learn() == {"FINISHED"}
    seen = []
    while operators._tick() is not None:
        seen.append(scene.sinmdm.progress)
        time.sleep(0.25)
    report["resume"] = {
        "progress_seen": sorted(set(round(p, 3) for p in seen)),
        "lines": [line for line in jobs.last().lines if "from step" in line],
        "model": (run.parent / "model.onnx").exists(),
        "message": scene.sinmdm.message,
    }
    # The picture: the source and the two generated actions at their widest poses.
    sys.path.insert(0, str(pathlib.Path(__file__).parent))
    import picture

    picture.skin_boxes(arm, 0.02 * float(np.ptp(heads["heads_0"][0, :, 2])))
    picture.render_side_by_side(arm, [source, *made], str(OUT / "blender_addon.png"))
    (OUT / "report.json").write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()

"""What each button asks of `sinmdm` and `sinmdm-train`, and where it puts the results: the
command lines and files, with no UI. The operators run these as background jobs."""

import json
import os
import re
import subprocess

import bpy
import numpy as np

from . import actions, jobs, preferences
from .rig import Rig, RigError

MODEL_KEY = "sinmdm_model"
RUN_KEY = "sinmdm_run"
ACTION_KEY = "sinmdm_action"


def scene_fps(scene):
    return scene.render.fps / scene.render.fps_base


def source(context):
    """(armature object, its active action) or a RigError saying what to select."""
    obj = context.active_object
    if obj is None or obj.type != "ARMATURE":
        raise RigError("select an armature: the active object is not one")
    anim = obj.animation_data
    if anim is None or anim.action is None:
        raise RigError(f"'{obj.name}' has no active action to learn from (assign one in the Action Editor)")
    return obj, anim.action


def frame_range(scene, action, use_scene):
    if use_scene:
        return scene.frame_start, scene.frame_end
    first, last = action.frame_range
    return int(round(first)), int(round(last))


def _safe(name):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "clip"


def run_folder(obj, action):
    """The folder of this armature's run on `action`: the one Learn last used for it, else a new
    one beside a saved .blend, else in the preferences' folder."""
    if obj.get(ACTION_KEY) == action.name and RUN_KEY in obj and os.path.isdir(bpy.path.abspath(obj[RUN_KEY])):
        return bpy.path.abspath(obj[RUN_KEY])
    if bpy.data.filepath:
        base = os.path.join(os.path.dirname(bpy.data.filepath), "sinmdm")
    else:
        base = bpy.path.abspath(preferences.prefs().work_folder)
    return os.path.join(base, _safe(f"{obj.name}_{action.name}"))


def _stored_path(path):
    """A path as kept in a custom property: relative to the .blend where it is saved."""
    if bpy.data.filepath:
        try:
            return bpy.path.relpath(path)
        except ValueError:
            return path
    return path


def _has_checkpoint(run):
    """Whether the trainer saved a checkpoint (a `step-*` file or folder) under `run`."""
    return any(
        name.startswith("step-") for _, dirs, files in os.walk(run) for name in dirs + files
    )


def clip_text(context, obj, action):
    """The action sampled over its frame range (or the scene's) as world-space BVH text."""
    scene = context.scene
    settings = scene.sinmdm
    rig = Rig(obj)
    first, last = frame_range(scene, action, settings.use_scene_range)
    if last - first < 2:
        raise RigError(f"the frame range {first}..{last} is too short to learn from")
    return rig.to_bvh(rig.sample(scene, action, first, last), scene_fps(scene))


def learn_job(context):
    """The training job for the active action: a new run, or the stopped one resumed when its
    clip is the same. The model is exported beside the run and remembered on the armature."""
    obj, action = source(context)
    settings = context.scene.sinmdm
    folder = run_folder(obj, action)
    clip = os.path.join(folder, "clip.bvh")
    run = os.path.join(folder, "run")
    model = os.path.join(folder, "model.onnx")
    text = clip_text(context, obj, action)
    same_clip = os.path.isfile(clip) and open(clip, encoding="utf-8").read() == text
    train = preferences.find_binary("sinmdm-train")
    if train is None:
        raise RigError(preferences.check())
    if same_clip and _has_checkpoint(run):
        # The run's own config: a resumed run keeps the settings it started with.
        argv = [train, "--resume", "--out", run, "--export", model]
        resumed = True
    else:
        if os.path.exists(run):
            folder = _fresh(folder)
            clip, run, model = (os.path.join(folder, n) for n in ("clip.bvh", "run", "model.onnx"))
        os.makedirs(folder, exist_ok=True)
        with open(clip, "w", encoding="utf-8") as f:
            f.write(text)
        argv = [train, clip, "--out", run, "--export", model]
        if settings.config:
            argv += ["--config", bpy.path.abspath(settings.config)]
        if settings.minutes > 0:
            argv += ["--minutes", f"{settings.minutes:g}"]
        argv += ["--root-layout", settings.root_layout]
        resumed = False
    obj[RUN_KEY] = _stored_path(folder)
    obj[ACTION_KEY] = action.name
    obj_name = obj.name

    def finish(job):
        target = bpy.data.objects.get(obj_name)
        if job.cancelled:
            return "INFO", "Learn stopped at a checkpoint; Learn again resumes it"
        if job.process.returncode != 0 or not os.path.isfile(model):
            return "ERROR", job.error()
        if target is not None:
            target[MODEL_KEY] = _stored_path(model)
        return "INFO", f"learned {action.name}{' (resumed)' if resumed else ''}: {model}"

    return jobs.Job("Learn", argv, finish)


def _fresh(folder):
    n = 2
    while os.path.exists(f"{folder}_{n}"):
        n += 1
    return f"{folder}_{n}"


def model_of(obj):
    if MODEL_KEY not in obj:
        raise RigError(f"'{obj.name}' has no learned model yet: press Learn first")
    path = bpy.path.abspath(obj[MODEL_KEY])
    if not os.path.isfile(path):
        raise RigError(f"the model of '{obj.name}' is missing: {path} (Learn again)")
    return path


def model_fps(model):
    sinmdm = preferences.find_binary("sinmdm")
    info = subprocess.run([sinmdm, "info", model, "--json"], capture_output=True, text=True, check=True)
    return float(json.loads(info.stdout)["layout"]["fps"])


def _outputs(path, count):
    stem, ext = os.path.splitext(path)
    return [path] if count == 1 else [f"{stem}_{i:03d}{ext}" for i in range(count)]


def sampling_job(context, task):
    """The job for one sampling task ('generate', 'inbetween', 'expand', 'steer', 'dance'); when
    it ends, each sample becomes a new action of the same armature on an NLA track."""
    scene = context.scene
    settings = scene.sinmdm
    obj, action = source(context)
    Rig(obj)  # a rig the add-on cannot use is refused before anything runs
    model = model_of(obj)
    sinmdm = preferences.find_binary("sinmdm")
    if sinmdm is None:
        raise RigError(preferences.check())
    folder = os.path.join(run_folder(obj, action), "generated")
    os.makedirs(folder, exist_ok=True)
    n = 1
    while os.path.exists(os.path.join(folder, f"{task}_{n:03d}")):
        n += 1
    out_dir = os.path.join(folder, f"{task}_{n:03d}")
    os.makedirs(out_dir)
    output = os.path.join(out_dir, "out.bvh")
    count = settings.count
    fps = scene_fps(scene)
    first, last = frame_range(scene, action, settings.use_scene_range)
    argv = [sinmdm, task, "-m", model, "-o", output, "--count", count, "--seed", settings.seed]
    argv += ["--steps", settings.steps, "--quiet"]
    place = {"start": first, "gap": None}

    def reference():
        ref = os.path.join(out_dir, "reference.bvh")
        text = clip_text(context, obj, action)
        with open(ref, "w", encoding="utf-8") as f:
            f.write(text)
        return ["--reference", ref]

    if task == "generate":
        argv += ["--seconds", f"{settings.seconds:g}"]
    elif task == "inbetween":
        after, before = gap(scene)
        if not first <= after < before <= last:
            raise RigError(f"the gap {after}..{before} must lie inside the action's frames {first}..{last}")
        argv += reference()
        argv += ["--keep", f"0:{(after - first + 1) / fps:.6f}s", "--keep", f"{(before - first) / fps:.6f}s:"]
        place["gap"] = (after, before)
    elif task == "expand":
        argv += reference() + ["--prefix", f"{settings.prefix:g}s", "--suffix", f"{settings.suffix:g}s"]
        place["start"] = first - settings.prefix * fps
    elif task == "steer":
        argv += ["--path", curve_path(settings.curve, settings.seconds, model_fps(model), out_dir)]
    elif task == "dance":
        music, start = sound_strip(scene)
        argv += reference() + ["--music", music]
        place["start"] = start
    source_name, obj_name, seed = action.name, obj.name, settings.seed

    def finish(job):
        if job.cancelled:
            return "INFO", f"{task} cancelled"
        if job.process.returncode != 0:
            return "ERROR", job.error()
        target = bpy.data.objects.get(obj_name)
        made = apply_outputs(Rig(target), _outputs(output, count), source_name, task, seed, place, fps)
        return "INFO", f"{task}: {len(made)} new action(s) on '{obj_name}': {', '.join(a.name for a in made)}"

    return jobs.Job(task.capitalize(), argv, finish)


def apply_outputs(rig, files, source_name, task, seed, place, fps):
    """Each output clip as a new action on the rig, pushed to its own NLA track."""
    made = []
    src = bpy.data.actions.get(source_name)
    for i, path in enumerate(files):
        with open(path, encoding="utf-8") as f:
            bones, bases, frame_time = rig.bases_from_bvh(f.read())
        frames = place["start"] + np.arange(bases.shape[0]) * frame_time * fps
        name = f"{source_name}_{task}_seed{seed}" + (f"_{i + 1}" if len(files) > 1 else "")
        if place["gap"] is not None:
            action = src.copy()
            action.name = name
            action.use_fake_user = True
            after, before = place["gap"]
            actions.replace_keys_between(rig, action, bones, bases, frames, after, before)
        else:
            action = actions.write_action(rig, name, bones, bases, frames)
        actions.push_to_nla(rig.obj, action, frames[0] if place["gap"] is None else action.frame_range[0])
        made.append(action)
    return made


def gap(scene):
    """The frames (after, before) around the gap: the preview range, else two markers."""
    if scene.use_preview_range:
        return scene.frame_preview_start, scene.frame_preview_end
    markers = sorted(m.frame for m in scene.timeline_markers if m.select) or sorted(
        m.frame for m in scene.timeline_markers
    )
    if len(markers) != 2:
        raise RigError("mark the gap: set the preview range (Ctrl+Alt+P) or place two markers around it")
    return markers[0], markers[1]


def curve_path(curve, seconds, fps, out_dir):
    """A path file for `sinmdm steer`: the curve walked at even speed in `seconds`, one world
    position per model frame."""
    if curve is None or curve.type != "CURVE":
        raise RigError("pick a curve object to steer along")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = curve.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        points = np.array([curve.matrix_world @ v.co for v in mesh.vertices])
    finally:
        evaluated.to_mesh_clear()
    if len(points) < 2:
        raise RigError(f"the curve '{curve.name}' has fewer than two points")
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    frames = max(2, int(round(seconds * fps)))
    s = np.linspace(0.0, arc[-1], frames)
    path = np.stack([np.interp(s, arc, points[:, k]) for k in range(3)], axis=1)
    file = os.path.join(out_dir, "path.csv")
    np.savetxt(file, path, delimiter=",", fmt="%.6f")
    return file


def sound_strip(scene):
    """(the audio file of the scene's first sound strip, its start frame)."""
    editor = scene.sequence_editor
    strips = []
    if editor is not None:
        every = getattr(editor, "strips_all", None) or editor.sequences_all
        strips = sorted((s for s in every if s.type == "SOUND"), key=lambda s: s.frame_start)
    if not strips:
        raise RigError("add the music as a sound strip in the Video Sequencer first")
    strip = strips[0]
    return bpy.path.abspath(strip.sound.filepath), strip.frame_start

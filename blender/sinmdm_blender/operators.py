"""The panel's buttons. Each starts a background job and returns at once, so the UI never
freezes; a timer moves the progress bar and applies the result when the job ends. Without a
window (Blender run headless, `--background`), or with `blocking`, the operator waits instead."""

import bpy

from . import jobs, tasks
from .rig import RigError


def _redraw():
    wm = bpy.context.window_manager
    for window in getattr(wm, "windows", []):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _end(job):
    """Applies a finished job on the main thread and reports what it did."""
    jobs.clear()
    scene = bpy.context.scene
    try:
        level, message = job.finish(job)
    except (RigError, OSError, ValueError) as e:
        level, message = "ERROR", str(e)
    scene.sinmdm.progress = 1.0 if level == "INFO" and not job.cancelled else scene.sinmdm.progress
    scene.sinmdm.message = message.splitlines()[0] if message else ""
    print(f"sinmdm: {message}")
    return level, message


def _tick():
    job = jobs.current()
    if job is None:
        return None
    bpy.context.scene.sinmdm.progress = job.progress
    if job.running():
        _redraw()
        return 0.25
    job.wait()
    _end(job)
    _redraw()
    return None


class _Background:
    blocking: bpy.props.BoolProperty(default=False, options={"HIDDEN", "SKIP_SAVE"})

    @classmethod
    def poll(cls, context):
        return jobs.current() is None

    def make_job(self, context):
        raise NotImplementedError

    def execute(self, context):
        try:
            job = self.make_job(context)
        except (RigError, OSError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        jobs.start(job)
        context.scene.sinmdm.progress = 0.0
        context.scene.sinmdm.message = f"{job.label}…"
        if self.blocking or bpy.app.background:
            job.wait()
            level, message = _end(job)
            self.report({level}, message)
            return {"FINISHED"} if level == "INFO" else {"CANCELLED"}
        bpy.app.timers.register(_tick, first_interval=0.25)
        return {"FINISHED"}


class SINMDM_OT_learn(_Background, bpy.types.Operator):
    """Learn the active action of the active armature (in the background; Cancel stops it at a checkpoint)"""

    bl_idname = "sinmdm.learn"
    bl_label = "Learn"

    def make_job(self, context):
        return tasks.learn_job(context)


class SINMDM_OT_start_learn(bpy.types.Operator):
    """Start Learn and return at once even without a window (for scripts that then Cancel)"""

    bl_idname = "sinmdm.start_learn"
    bl_label = "Start Learn"
    bl_options = {"INTERNAL"}

    def execute(self, context):
        try:
            jobs.start(tasks.learn_job(context))
        except (RigError, OSError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        if not bpy.app.background:
            bpy.app.timers.register(_tick, first_interval=0.25)
        return {"FINISHED"}


class SINMDM_OT_cancel(bpy.types.Operator):
    """Stop the running job; a Learn stops at a checkpoint that the next Learn resumes"""

    bl_idname = "sinmdm.cancel"
    bl_label = "Cancel"

    @classmethod
    def poll(cls, context):
        return jobs.current() is not None

    def execute(self, context):
        job = jobs.current()
        job.cancel()
        level, message = _end(job)
        self.report({level}, message)
        return {"FINISHED"}


def _sampling(idname, label, task, doc):
    def make_job(self, context):
        return tasks.sampling_job(context, task)

    return type(
        f"SINMDM_OT_{task}",
        (_Background, bpy.types.Operator),
        {"bl_idname": idname, "bl_label": label, "__doc__": doc, "make_job": make_job},
    )


SAMPLING = [
    _sampling("sinmdm.generate", "Generate", "generate", "New actions of the set length, one per sample"),
    _sampling(
        "sinmdm.inbetween",
        "In-between",
        "inbetween",
        "Keep the action's keys outside the preview range (or two markers), generate the gap",
    ),
    _sampling("sinmdm.expand", "Expand", "expand", "New motion before and after the action"),
    _sampling("sinmdm.steer", "Steer along curve", "steer", "Walk along the chosen curve (heading-relative models)"),
    _sampling("sinmdm.dance", "Dance to sound strip", "dance", "A dance as long as the scene's sound strip"),
]

CLASSES = [SINMDM_OT_learn, SINMDM_OT_start_learn, SINMDM_OT_cancel, *SAMPLING]

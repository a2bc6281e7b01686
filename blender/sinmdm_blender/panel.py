"""The sidebar panel (3D view, N, tab "SinMDM") and the scene's settings it shows."""

import bpy

from . import jobs, tasks


def _is_curve(_self, obj):
    return obj.type == "CURVE"


class SinmdmSettings(bpy.types.PropertyGroup):
    use_scene_range: bpy.props.BoolProperty(
        name="Scene range", description="Learn the scene's frame range instead of the action's"
    )
    config: bpy.props.StringProperty(
        name="Config", description="A training configuration (YAML); empty: the default", subtype="FILE_PATH"
    )
    minutes: bpy.props.FloatProperty(
        name="Minutes", description="Training time budget; 0: the trainer's default", min=0.0, default=0.0
    )
    root_layout: bpy.props.EnumProperty(
        name="Root",
        description="How the model describes the root's motion",
        items=[
            ("auto", "Auto", "Heading-relative where the clip travels and has a facing, world otherwise"),
            ("heading", "Heading (steerable)", "Speeds and turns in the character's facing: Steer needs this"),
            ("world", "World", "Ground displacement in world axes"),
        ],
        default="auto",
    )
    count: bpy.props.IntProperty(name="Actions", description="How many new actions", min=1, max=64, default=3)
    seconds: bpy.props.FloatProperty(name="Seconds", description="Length of each", min=0.5, default=8.0)
    seed: bpy.props.IntProperty(name="Seed", description="Same seed, same motion", min=0, default=0)
    steps: bpy.props.IntProperty(name="Steps", description="Denoising steps", min=1, max=1000, default=50)
    prefix: bpy.props.FloatProperty(name="Before (s)", min=0.0, default=2.0)
    suffix: bpy.props.FloatProperty(name="After (s)", min=0.0, default=2.0)
    curve: bpy.props.PointerProperty(name="Curve", type=bpy.types.Object, poll=_is_curve)
    progress: bpy.props.FloatProperty(name="Progress", min=0.0, max=1.0, subtype="FACTOR")
    message: bpy.props.StringProperty(name="Message")


class SINMDM_PT_panel(bpy.types.Panel):
    bl_label = "SinMDM"
    bl_idname = "SINMDM_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "SinMDM"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sinmdm
        obj = context.active_object
        box = layout.box()
        box.label(text="Learn", icon="ARMATURE_DATA")
        if obj is not None and obj.type == "ARMATURE" and obj.animation_data and obj.animation_data.action:
            box.label(text=f"{obj.name}: {obj.animation_data.action.name}")
        box.prop(settings, "use_scene_range")
        box.prop(settings, "minutes")
        box.prop(settings, "root_layout")
        box.prop(settings, "config")
        box.operator("sinmdm.learn", icon="PLAY")
        if obj is not None and tasks.MODEL_KEY in obj:
            box.label(text=f"model: {obj[tasks.MODEL_KEY]}", icon="CHECKMARK")

        box = layout.box()
        box.label(text="Make", icon="ACTION")
        row = box.row(align=True)
        row.prop(settings, "count")
        row.prop(settings, "seed")
        row = box.row(align=True)
        row.prop(settings, "seconds")
        row.prop(settings, "steps")
        box.operator("sinmdm.generate", icon="ADD")
        box.operator("sinmdm.inbetween", icon="ARROW_LEFTRIGHT")
        row = box.row(align=True)
        row.prop(settings, "prefix")
        row.prop(settings, "suffix")
        box.operator("sinmdm.expand", icon="FULLSCREEN_ENTER")
        box.prop(settings, "curve")
        box.operator("sinmdm.steer", icon="CURVE_PATH")
        box.operator("sinmdm.dance", icon="SOUND")

        job = jobs.current()
        if job is not None or settings.message:
            box = layout.box()
            if job is not None:
                label = f"{job.label}: {settings.progress * 100:.0f} %"
                if hasattr(box, "progress"):
                    box.progress(factor=settings.progress, type="BAR", text=label)
                else:
                    box.label(text=label)
                box.operator("sinmdm.cancel", icon="CANCEL")
            if settings.message:
                box.label(text=settings.message)


CLASSES = [SinmdmSettings, SINMDM_PT_panel]

"""SinMDM for Blender: learn the active action of an armature and make new actions on the same
rig (generate, in-between, expand, steer along a curve, dance to a sound strip), with the
`sinmdm` programs running in the background."""

bl_info = {
    "name": "SinMDM",
    "author": "sinmdm-rs contributors",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "3D Viewport > Sidebar > SinMDM",
    "description": "Learn one action, generate new actions on the same armature",
    "category": "Animation",
}

import bpy  # noqa: E402

from . import operators, panel, preferences  # noqa: E402

_CLASSES = [preferences.SinmdmPreferences, *panel.CLASSES, *operators.CLASSES]


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sinmdm = bpy.props.PointerProperty(type=panel.SinmdmSettings)
    prefs = preferences.prefs()
    prefs.status = preferences.check(prefs.binaries or None)
    if prefs.status:
        print(f"SinMDM: {prefs.status}")


def unregister():
    del bpy.types.Scene.sinmdm
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)

"""Where the add-on finds `sinmdm` and `sinmdm-train`, and where runs go when the .blend is not
saved yet; both checked on enable, with a message that names what is missing."""

import os
import shutil
import subprocess

import bpy

BINARIES = ("sinmdm", "sinmdm-train")


def addon_key():
    """The add-on's name in Blender's preferences (a legacy add-on or an extension)."""
    return __package__


def prefs():
    return bpy.context.preferences.addons[addon_key()].preferences


def find_binary(name, folder=None):
    """The path of `name` in the preferences' folder, else on PATH, else None."""
    folder = folder if folder is not None else prefs().binaries
    exe = name + (".exe" if os.name == "nt" else "")
    if folder:
        path = os.path.join(bpy.path.abspath(folder), exe)
        return path if os.path.isfile(path) else None
    return shutil.which(exe)


def check(folder=None):
    """'' when both programs are found and `sinmdm` finds onnxruntime, else what is missing."""
    missing = [n for n in BINARIES if not find_binary(n, folder)]
    where = f"in '{folder}'" if folder else "on PATH"
    if missing:
        return (
            f"{' and '.join(missing)} not found {where}: set the folder that holds them in the "
            "add-on's preferences (cargo install --path cli and --path train put them in ~/.cargo/bin)"
        )
    doctor = subprocess.run(
        [find_binary("sinmdm", folder), "doctor"], capture_output=True, text=True, errors="replace"
    )
    if doctor.returncode != 0:
        lines = (doctor.stdout + doctor.stderr).strip().splitlines()
        return "sinmdm cannot load onnxruntime: " + (lines[-1] if lines else f"doctor exited {doctor.returncode}")
    return ""


def _rechecked(self, _context):
    self.status = check(self.binaries or None)


class SinmdmPreferences(bpy.types.AddonPreferences):
    bl_idname = addon_key()

    binaries: bpy.props.StringProperty(
        name="Programs folder",
        description="The folder holding sinmdm and sinmdm-train (empty: found on PATH)",
        subtype="DIR_PATH",
        update=_rechecked,
    )
    work_folder: bpy.props.StringProperty(
        name="Runs folder",
        description="Where runs and models go while the .blend is not saved (a saved .blend keeps them beside it)",
        subtype="DIR_PATH",
        default=os.path.join(os.path.expanduser("~"), "sinmdm_runs"),
    )
    status: bpy.props.StringProperty(name="Status", default="")

    def draw(self, _context):
        layout = self.layout
        layout.prop(self, "binaries")
        layout.prop(self, "work_folder")
        if self.status:
            for line in _wrapped(self.status):
                layout.label(text=line, icon="ERROR")
        else:
            layout.label(text="sinmdm and sinmdm-train found", icon="CHECKMARK")


def _wrapped(text, width=90):
    words, line, out = text.split(), "", []
    for w in words:
        if len(line) + len(w) + 1 > width:
            out.append(line)
            line = w
        else:
            line = f"{line} {w}".strip()
    return out + [line]

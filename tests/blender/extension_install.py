"""Installs the packaged zip as a Blender 4.2+ extension (its blender_manifest.toml) in a
headless Blender and prints the add-ons then enabled and the SinMDM operators registered.

Run: python extension_install.py ADDON.zip
"""

import sys

import bpy

bpy.ops.wm.read_factory_settings(use_empty=True)
result = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
print("installed", sorted(result))
print("enabled", [name for name in bpy.context.preferences.addons.keys() if "sinmdm" in name])
print("operators", sorted(name for name in dir(bpy.ops.sinmdm)))

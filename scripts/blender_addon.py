#!/usr/bin/env python3
"""Packages the Blender add-on (blender/sinmdm_blender) into an installable zip.

Run: python3 scripts/blender_addon.py [OUT.zip]   (default: target/sinmdm_blender.zip)
Install: Blender > Edit > Preferences > Add-ons > Install from Disk, pick the zip, tick SinMDM.
The zip holds the one folder `sinmdm_blender/` with `bl_info` and `blender_manifest.toml`.
"""

import pathlib
import sys
import zipfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCE = ROOT / "blender" / "sinmdm_blender"


def package(out):
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_suffix(".zip.partial")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(SOURCE.rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts:
                z.write(path, pathlib.Path("sinmdm_blender") / path.relative_to(SOURCE))
    partial.replace(out)
    return out


if __name__ == "__main__":
    target = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "sinmdm_blender.zip"
    print(package(target))

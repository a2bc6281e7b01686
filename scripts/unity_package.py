#!/usr/bin/env python3
"""Builds the Unity package of sinmdm (UPM layout) from the repository, in one command:

    python3 scripts/unity_package.py [--out DIR] [--no-build]

It builds the C ABI (release), then writes DIR/com.sinmdm.runtime (default DIR: target/unity):
package.json; Runtime/ with the C# binding, a streaming component and an assembly definition;
the native libraries under Plugins/<platform>/<arch>/ (this machine's: sinmdm_c and the
onnxruntime it was tested with, side by side, so the runtime finds onnxruntime next to
sinmdm_c); a sample under Samples~/ with the shipped walk model; licences. Every file and folder
outside Samples~ gets a .meta with a GUID derived from its path, so a rebuilt package keeps its
GUIDs and Unity's references to them.

Add it in Unity with Package Manager > Add package from disk > DIR/com.sinmdm.runtime/package.json
(or `npm pack` it into a tarball and add that).
"""

import argparse
import glob
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAME = "com.sinmdm.runtime"


def workspace_version():
    with open(os.path.join(REPO, "Cargo.toml"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("version"):
                return line.split("=", 1)[1].strip().strip('"')
    raise SystemExit("no version in Cargo.toml")


def native_layout():
    """The Plugins folder, library file names and Unity platform name of this machine."""
    system, machine = platform.system(), platform.machine().lower()
    arch = {"x86_64": "x86_64", "amd64": "x86_64", "aarch64": "arm64", "arm64": "arm64"}.get(machine, machine)
    if system == "Linux":
        return f"Plugins/Linux/{arch}", "libsinmdm_c.so", "Linux", arch
    if system == "Darwin":
        return "Plugins/macOS", "libsinmdm_c.dylib", "OSX", arch
    if system == "Windows":
        return f"Plugins/Windows/{arch}", "sinmdm_c.dll", "Win64", arch
    raise SystemExit(f"no Unity plugin layout for {system}")


def guid(relative):
    """A stable GUID for a path inside the package."""
    return hashlib.md5(f"{NAME}/{relative}".encode()).hexdigest()


def folder_meta(relative):
    return f"fileFormatVersion: 2\nguid: {guid(relative)}\nfolderAsset: yes\nDefaultImporter:\n  externalObjects: {{}}\n  userData: \n  assetBundleName: \n  assetBundleVariant: \n"


def default_meta(relative):
    return f"fileFormatVersion: 2\nguid: {guid(relative)}\nDefaultImporter:\n  externalObjects: {{}}\n  userData: \n  assetBundleName: \n  assetBundleVariant: \n"


def script_meta(relative):
    return (
        f"fileFormatVersion: 2\nguid: {guid(relative)}\nMonoImporter:\n  externalObjects: {{}}\n"
        "  serializedVersion: 2\n  defaultReferences: []\n  executionOrder: 0\n  icon: {instanceID: 0}\n"
        "  userData: \n  assetBundleName: \n  assetBundleVariant: \n"
    )


def asmdef_meta(relative):
    return (
        f"fileFormatVersion: 2\nguid: {guid(relative)}\nAssemblyDefinitionImporter:\n  externalObjects: {{}}\n"
        "  userData: \n  assetBundleName: \n  assetBundleVariant: \n"
    )


def text_meta(relative):
    return (
        f"fileFormatVersion: 2\nguid: {guid(relative)}\nTextScriptImporter:\n  externalObjects: {{}}\n"
        "  userData: \n  assetBundleName: \n  assetBundleVariant: \n"
    )


def plugin_meta(relative, unity_platform, arch):
    """A native plugin enabled for the editor and the player of its platform and CPU."""
    editor_os = {"Linux": "Linux", "OSX": "OSX", "Win64": "Windows"}[unity_platform]
    cpu = {"x86_64": "x86_64", "arm64": "ARM64"}.get(arch, "AnyCPU")
    return (
        f"fileFormatVersion: 2\nguid: {guid(relative)}\nPluginImporter:\n  externalObjects: {{}}\n"
        "  serializedVersion: 2\n  iconMap: {}\n  executionOrder: {}\n  defineConstraints: []\n"
        "  isPreloaded: 0\n  isOverridable: 0\n  isExplicitlyReferenced: 0\n  validateReferences: 1\n"
        "  platformData:\n"
        "  - first:\n      Any: \n    second:\n      enabled: 0\n      settings: {}\n"
        "  - first:\n      Editor: Editor\n    second:\n      enabled: 1\n      settings:\n"
        f"        CPU: {cpu}\n        DefaultValueInitialized: true\n        OS: {editor_os}\n"
        f"  - first:\n      Standalone: {unity_platform}\n    second:\n      enabled: 1\n      settings:\n"
        f"        CPU: {cpu}\n"
        "  userData: \n  assetBundleName: \n  assetBundleVariant: \n"
    )


def meta_for(relative, unity_platform, arch):
    if relative.endswith(".cs"):
        return script_meta(relative)
    if relative.endswith(".asmdef"):
        return asmdef_meta(relative)
    if relative.endswith((".md", ".json", ".txt")):
        return text_meta(relative)
    if relative.startswith("Plugins/"):
        return plugin_meta(relative, unity_platform, arch)
    return default_meta(relative)


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def onnxruntime_library():
    found = sorted(glob.glob(os.path.join(REPO, ".venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.1*")))
    found += sorted(glob.glob(os.path.join(REPO, ".venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.*.dylib")))
    found += sorted(glob.glob(os.path.join(REPO, ".venv/Lib/site-packages/onnxruntime/capi/onnxruntime.dll")))
    if not found:
        raise SystemExit("no onnxruntime library in .venv: run scripts/setup_tests.sh first")
    return found[0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join(REPO, "target", "unity"))
    parser.add_argument("--no-build", action="store_true", help="use the release library already built")
    args = parser.parse_args(argv)

    if not args.no_build:
        subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "sinmdm-c", "--lib"], cwd=REPO, check=True)
    plugins, library, unity_platform, arch = native_layout()
    built = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(REPO, "target")), "release", library)
    if not os.path.isfile(built):
        raise SystemExit(f"no {built}: build the C ABI first (cargo build --release -p sinmdm-c)")

    root = os.path.join(os.path.abspath(args.out), NAME)
    if os.path.exists(root):
        shutil.rmtree(root)
    version = workspace_version()
    package = {
        "name": NAME,
        "version": version,
        "displayName": "sinmdm: motion from one clip",
        "description": "Single-motion diffusion at run time: new, varied motion from a model trained on one clip "
        "(crowds, in-betweens, endless streams), through onnxruntime. Same seed, same poses, on any core count.",
        "unity": "2021.3",
        "license": "MIT OR Apache-2.0",
        "keywords": ["animation", "motion", "diffusion", "procedural"],
        "samples": [
            {
                "displayName": "Walker",
                "description": "A character walking forever from the shipped CMU walk model.",
                "path": "Samples~/Walker",
            }
        ],
    }
    write(os.path.join(root, "package.json"), json.dumps(package, indent=2) + "\n")
    asmdef = {
        "name": "Sinmdm.Runtime",
        "rootNamespace": "Sinmdm",
        "references": [],
        "includePlatforms": [],
        "excludePlatforms": [],
        "allowUnsafeCode": False,
        "overrideReferences": False,
        "precompiledReferences": [],
        "autoReferenced": True,
        "defineConstraints": [],
        "versionDefines": [],
        "noEngineReferences": False,
    }
    write(os.path.join(root, "Runtime", "Sinmdm.Runtime.asmdef"), json.dumps(asmdef, indent=2) + "\n")
    for source in sorted(glob.glob(os.path.join(REPO, "bindings", "csharp", "*.cs"))):
        shutil.copyfile(source, os.path.join(root, "Runtime", os.path.basename(source)))
    for component in ["SinmdmAnimator.cs", "SinmdmCrowdAnimator.cs"]:
        shutil.copyfile(os.path.join(REPO, "bindings", "unity", component), os.path.join(root, "Runtime", component))
    os.makedirs(os.path.join(root, plugins), exist_ok=True)
    shutil.copyfile(built, os.path.join(root, plugins, library))
    ort = onnxruntime_library()
    shutil.copyfile(ort, os.path.join(root, plugins, os.path.basename(ort)))
    sample = os.path.join(root, "Samples~", "Walker")
    os.makedirs(sample)
    shutil.copyfile(os.path.join(REPO, "bindings", "unity", "WalkerSample.cs"), os.path.join(sample, "WalkerSample.cs"))
    # Unity imports .bytes files as TextAssets: the model is handed to Model.FromBytes.
    shutil.copyfile(os.path.join(REPO, "onnx-models", "human_walk_cmu.onnx"), os.path.join(sample, "human_walk_cmu.bytes"))
    shutil.copyfile(os.path.join(REPO, "onnx-models", "human_walk_cmu.md"), os.path.join(sample, "human_walk_cmu.md"))
    shutil.copyfile(os.path.join(REPO, "LICENSE-MIT"), os.path.join(root, "LICENSE.md"))
    write(
        os.path.join(root, "Third Party Notices.md"),
        "# Third-party notices\n\n"
        f"`{plugins}/{os.path.basename(ort)}` is onnxruntime (https://onnxruntime.ai), "
        "Copyright (c) Microsoft Corporation, under the MIT licence.\n\n"
        "`Samples~/Walker/human_walk_cmu.bytes` was trained on a clip of the CMU Graphics Lab Motion Capture "
        "Database (mocap.cs.cmu.edu); see its card, `human_walk_cmu.md`.\n",
    )
    write(
        os.path.join(root, "README.md"),
        "# sinmdm for Unity\n\n"
        "New, varied motion at run time from a model trained on one clip. `Runtime/Sinmdm*.cs` are the C# binding "
        "(models, tasks, stepped runs, endless streams, progress and cancel); `Runtime/SinmdmAnimator.cs` plays a "
        "stream on a character's bones, preparing frames a few denoising steps per frame so no frame waits; "
        "`Runtime/SinmdmCrowdAnimator.cs` plays one crowd of many characters, each with its own seed and turn. "
        "The sample `Walker` uses the shipped CMU walk.\n\n"
        f"Native libraries: `{plugins}/` (built for this platform by `scripts/unity_package.py`; onnxruntime sits "
        "next to sinmdm_c, where the runtime looks for it). Same model, seed and settings give the same poses on any "
        "core count.\n",
    )
    # Metas for every file and folder outside Samples~ (Unity ignores folders ending in ~).
    for directory, folders, files in os.walk(root):
        folders[:] = [d for d in folders if not d.endswith("~")]
        for name in folders + files:
            if name.endswith(".meta"):
                continue
            path = os.path.join(directory, name)
            relative = os.path.relpath(path, root).replace(os.sep, "/")
            meta = folder_meta(relative) if os.path.isdir(path) else meta_for(relative, unity_platform, arch)
            write(path + ".meta", meta)
    print(root)
    return 0


if __name__ == "__main__":
    sys.exit(main())

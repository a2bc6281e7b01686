"""The Unity package that `scripts/unity_package.py` builds: its JSON, assembly definition and
.meta files parse (PyYAML reads the metas), every file and folder has a .meta with a unique
GUID, every native library has a plugin .meta, `npm pack` takes it, its Runtime/ compiles with
mcs against a stub of the UnityEngine types it uses, and the Mono checks run from the package's
own layout, finding onnxruntime next to sinmdm_c with no environment variable to help."""

import json
import os
import pathlib
import shutil
import subprocess
import sys
import tarfile

import pytest
import yaml

from conftest import ROOT

NAME = "com.sinmdm.runtime"


@pytest.fixture(scope="module")
def package(tmp_path_factory):
    out = tmp_path_factory.mktemp("unity")
    done = subprocess.run([sys.executable, ROOT / "scripts" / "unity_package.py", "--out", out],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    root = out / NAME
    assert root.is_dir()
    return root


def test_manifest_and_assembly_definition_parse(package):
    manifest = json.loads((package / "package.json").read_text())
    assert manifest["name"] == NAME
    assert manifest["version"].count(".") == 2
    assert manifest["unity"] == "2021.3"
    assert (package / manifest["samples"][0]["path"]).is_dir()
    asmdef = json.loads((package / "Runtime" / "Sinmdm.Runtime.asmdef").read_text())
    assert asmdef["name"] == "Sinmdm.Runtime"


def test_every_file_and_folder_has_a_meta_with_a_unique_guid(package):
    guids = {}
    for path in sorted(package.rglob("*")):
        relative = path.relative_to(package)
        if any(part.endswith("~") for part in relative.parts) or path.suffix == ".meta":
            continue
        meta = path.with_name(path.name + ".meta")
        assert meta.is_file(), f"{relative} has no .meta"
        data = yaml.safe_load(meta.read_text())
        assert data["fileFormatVersion"] == 2
        guid = data["guid"]
        assert len(guid) == 32 and all(c in "0123456789abcdef" for c in guid), guid
        assert guid not in guids, f"{relative} and {guids.get(guid)} share a GUID"
        guids[guid] = relative
        if path.is_dir():
            assert data["folderAsset"] is True
    for meta in package.rglob("*.meta"):
        assert meta.with_name(meta.name[: -len(".meta")]).exists(), f"{meta} belongs to nothing"


def test_native_libraries_are_plugins_for_their_platform(package):
    natives = [p for p in package.rglob("*") if p.is_file() and (".so" in p.name or p.suffix in (".dll", ".dylib"))
               and p.suffix != ".meta"]
    names = {p.name for p in natives}
    assert "libsinmdm_c.so" in names and any(n.startswith("libonnxruntime.so") for n in names), names
    for native in natives:
        assert native.parent.relative_to(package).parts[0] == "Plugins"
        meta = yaml.safe_load(native.with_name(native.name + ".meta").read_text())
        platforms = meta["PluginImporter"]["platformData"]
        enabled = [entry["first"] for entry in platforms if entry["second"]["enabled"] == 1]
        assert {"Editor": "Editor"} in enabled and {"Standalone": "Linux"} in enabled, platforms


def test_npm_pack_takes_the_package(package, tmp_path):
    if shutil.which("npm") is None:
        pytest.skip("npm is not installed (scripts/setup_tests.sh needs node and npm)")
    done = subprocess.run(["npm", "pack", str(package), "--pack-destination", str(tmp_path), "--silent"],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    tarball = tmp_path / done.stdout.strip().splitlines()[-1]
    with tarfile.open(tarball) as t:
        names = set(t.getnames())
    for needed in ["package/package.json", "package/Runtime/Sinmdm.cs", "package/Runtime/Sinmdm.Native.cs", "package/Runtime/Sinmdm.Runtime.asmdef",
                   "package/Plugins/Linux/x86_64/libsinmdm_c.so", "package/Plugins/Linux/x86_64/libsinmdm_c.so.meta"]:
        assert needed in names, needed


def test_runtime_compiles_against_the_unity_stub(package, tmp_path):
    sources = sorted(str(p) for p in (package / "Runtime").glob("*.cs"))
    done = subprocess.run(["mcs", "-warnaserror+", "-target:library", "-define:UNITY_5_3_OR_NEWER",
                           f"-out:{tmp_path / 'Sinmdm.Runtime.dll'}", str(ROOT / "tests" / "unity" / "UnityEngineStub.cs"),
                           *sources, str(package / "Samples~" / "Walker" / "WalkerSample.cs")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_mono_checks_run_from_the_package_layout(package, tmp_path):
    exe = tmp_path / "checks.exe"
    binding = sorted(str(p) for p in (package / "Runtime").glob("Sinmdm*.cs") if not p.name.endswith("Animator.cs"))
    done = subprocess.run(["mcs", "-warnaserror+", f"-out:{exe}", *binding,
                           str(ROOT / "capi" / "tests" / "csharp" / "Checks.cs")], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    plugins = package / "Plugins" / "Linux" / "x86_64"
    env = {k: v for k, v in os.environ.items() if k not in ("ORT_DYLIB_PATH", "LD_LIBRARY_PATH")}
    env["LD_LIBRARY_PATH"] = str(plugins)
    # Run outside the checkout: no .venv above the working directory, so onnxruntime must be
    # found next to sinmdm_c, as in a game.
    done = subprocess.run(["mono", str(exe), str(package / "Samples~" / "Walker" / "human_walk_cmu.bytes")],
                          capture_output=True, text=True, cwd=tmp_path, env=env)
    assert done.returncode == 0 and " passed, 0 failed" in done.stdout, done.stdout + done.stderr


def test_the_crowd_component_animates_a_crowd_headless(package, tmp_path):
    """SinmdmCrowdAnimator from the package, run under Mono against the UnityEngine stand-ins
    (tests/unity/CrowdCheck.cs): eight walkers of one crowd, each turning its own way, and
    character 0 bit for bit its stream alone."""
    exe = tmp_path / "crowd.exe"
    sources = sorted(str(p) for p in (package / "Runtime").glob("*.cs"))
    done = subprocess.run(["mcs", "-warnaserror+", "-define:UNITY_5_3_OR_NEWER", f"-out:{exe}",
                           str(ROOT / "tests" / "unity" / "UnityEngineStub.cs"), *sources,
                           str(ROOT / "tests" / "unity" / "CrowdCheck.cs")], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    plugins = package / "Plugins" / "Linux" / "x86_64"
    env = {k: v for k, v in os.environ.items() if k not in ("ORT_DYLIB_PATH", "LD_LIBRARY_PATH")}
    env["LD_LIBRARY_PATH"] = str(plugins)
    done = subprocess.run(["mono", str(exe), str(package / "Samples~" / "Walker" / "human_walk_cmu.bytes")],
                          capture_output=True, text=True, cwd=tmp_path, env=env)
    print(done.stdout)
    assert done.returncode == 0 and " passed, 0 failed" in done.stdout, done.stdout + done.stderr

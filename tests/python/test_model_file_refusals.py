"""Broken model files through the command line: `sinmdm generate` exits non-zero with an error
that names the problem and writes no output file; `sinmdm info` still shows what is readable.
The files are made with the `onnx` package, independently of the Rust code."""

import json
import subprocess

import onnx
import pytest

from conftest import ROOT, SINMDM

TINY = ROOT / "tests" / "data" / "models" / "walk_tiny.onnx"
METADATA_KEY = "sinmdm.metadata"


def broken_metadata(change):
    model = onnx.load(str(TINY))
    entry = next(e for e in model.metadata_props if e.key == METADATA_KEY)
    meta = json.loads(entry.value)
    change(meta)
    entry.value = json.dumps(meta)
    return model


def set_parent(meta, joint, parent):
    meta["layout"]["skeleton"]["joints"][joint]["parent"] = parent


def retype_steps(model):
    """The timestep input as float: the graph stays valid (its first node casts `t` to float),
    but the contract says int64."""
    t = next(i for i in model.graph.input if i.name == "t")
    t.type.tensor_type.elem_type = onnx.TensorProto.FLOAT
    return model


CASES = {
    "joint its own ancestor": (lambda m: set_parent(m, 3, 3), "layout.skeleton.joints[3].parent"),
    "parent outside the skeleton": (lambda m: set_parent(m, 2, 900), "layout.skeleton.joints[2].parent"),
    "no joints": (lambda m: m["layout"]["skeleton"].update(joints=[]), "layout.skeleton.joints"),
    "contact joint outside": (lambda m: m["layout"]["contact_joints"].append(400), "layout.contact_joints"),
    "absurd diffusion steps": (lambda m: m["diffusion"].update(steps=8_000_000_000_000), "diffusion.steps"),
    "negative frame rate": (lambda m: m["layout"].update(fps=-30), "layout.fps"),
    "wrong type": (lambda m: m["network"].update(channels="many"), "network.channels"),
}


def sinmdm(*args):
    return subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)


@pytest.mark.parametrize("case", sorted(CASES) + ["timestep retyped", "truncated file"])
def test_generate_refuses_a_broken_file_and_writes_nothing(tmp_path, case):
    bad = tmp_path / "bad.onnx"
    if case == "truncated file":
        bad.write_bytes(TINY.read_bytes()[:100_000])
        expected = "not a loadable ONNX model"
    elif case == "timestep retyped":
        onnx.save(retype_steps(onnx.load(str(TINY))), str(bad))
        expected = "'t' is"
    else:
        change, expected = CASES[case]
        onnx.save(broken_metadata(change), str(bad))
    out_dir = tmp_path / "out"
    done = sinmdm("generate", "-m", bad, "-o", out_dir / "sample.bvh", "--frames", 24,
                  "--steps", 2, "--quiet")
    assert done.returncode != 0
    assert expected in done.stderr, done.stderr
    assert "panicked" not in done.stderr
    assert not out_dir.exists() or not any(out_dir.iterdir())


def test_info_shows_a_broken_file_as_far_as_it_is_readable(tmp_path):
    bad = tmp_path / "bad.onnx"
    onnx.save(broken_metadata(lambda m: set_parent(m, 3, 3)), str(bad))
    done = sinmdm("info", bad)
    assert done.returncode != 0
    assert "skeleton" in done.stdout and "joints" in done.stdout, done.stdout
    assert "layout.skeleton.joints[3].parent" in done.stderr, done.stderr
    assert "not a usable model" in done.stderr

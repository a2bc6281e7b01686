"""The Rust runtime (`sinmdm`) and the Python reference (`python/sinmdm_reference`, numpy +
onnxruntime) give the same features for the same model, seed and arguments, task by task (and
for a stream); and the
command line refuses bad input with a clear message and no output file."""

import json
import subprocess
import sys

import numpy as np
import onnx
import pytest

from conftest import ROOT, SINMDM

MODEL = ROOT / "tests" / "data" / "models" / "walk_tiny.onnx"
WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"
HOP = ROOT / "tests" / "data" / "bvh" / "human_hop_cmu_131_03.bvh"
FOX = ROOT / "tests" / "data" / "bvh" / "fox_survey_khronos.bvh"


def normalizer():
    model = onnx.load(str(MODEL))
    meta = json.loads({p.key: p.value for p in model.metadata_props}["sinmdm.metadata"])
    mean = np.asarray(meta["normalizer"]["mean"], dtype=np.float32)
    std = np.asarray(meta["normalizer"]["std"], dtype=np.float32)
    return mean, std


def load(path):
    with open(path) as f:
        doc = json.load(f)
    return np.asarray(doc["samples"], dtype=np.float32)


def rust(*args):
    done = subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)
    return done


def python(*args):
    done = subprocess.run([sys.executable, "-m", "sinmdm_reference", *map(str, args)],
                          capture_output=True, text=True)
    return done


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    work = tmp_path_factory.mktemp("parity")
    out = {}
    for name, clip in [("walk", WALK), ("hop", HOP)]:
        path = work / f"{name}.json"
        done = rust("encode", clip, "-m", MODEL, "-o", path)
        assert done.returncode == 0, done.stderr
        out[name] = path
    out["work"] = work
    return out


CASES = {
    "generate-respaced": (["generate", "--frames", 90, "--count", 3, "--steps", 20], {}),
    "generate-all-steps": (["generate", "--frames", 48, "--steps", "all"], {}),
    "inbetween": (["inbetween", "--keep", "0:60", "--keep", "5s:", "--steps", 30], {"--reference": "walk"}),
    "inbetween-all-steps": (["inbetween", "--keep", ":40", "--keep", "100:", "--steps", "all"],
                            {"--reference": "walk"}),
    "expand": (["expand", "--prefix", "1s", "--suffix", 25, "--count", 2, "--steps", 25],
               {"--reference": "walk"}),
    "compose": (["compose", "--part", "LeftHip", "--joints", "Head,Neck", "--root", "--frames", "20:200",
                 "--steps", 25], {"--reference": "walk"}),
    "harmonize": (["harmonize", "--factor", 2, "--free-share", 0.1, "--steps", 40], {"--content": "hop"}),
    # Five blocks of 30 frames, each seeded from the stream's seed and continuing the last.
    "stream": (["stream", "--frames", 140, "--block", 30, "--steps", 12], {}),
    # Few-step samplers, with masks (x0 blending) and harmonization (x_t low-pass).
    "generate-dpm2m": (["generate", "--frames", 90, "--count", 2, "--steps", 12, "--sampler", "dpm2m"], {}),
    "generate-ddim-eta": (["generate", "--frames", 60, "--steps", 10, "--sampler", "ddim", "--eta", 0.5], {}),
    "inbetween-ddim": (["inbetween", "--keep", "0:60", "--keep", "5s:", "--steps", 10, "--sampler", "ddim"],
                       {"--reference": "walk"}),
    "compose-dpm2m": (["compose", "--part", "LeftHip", "--root", "--steps", 10, "--sampler", "dpm2m"],
                      {"--reference": "walk"}),
    "harmonize-dpm2m": (["harmonize", "--steps", 12, "--sampler", "dpm2m"], {"--content": "hop"}),
    "stream-dpm2m": (["stream", "--frames", 100, "--block", 30, "--steps", 8, "--sampler", "dpm2m"], {}),
    # The default blocks: the training clip's length.
    "stream-default-blocks": (["stream", "--frames", 400, "--steps", 4], {}),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_rust_and_python_agree(case, references):
    args, refs = CASES[case]
    work = references["work"]
    rust_json, py_json = work / f"{case}-rust.json", work / f"{case}-python.json"
    common = ["-m", MODEL, "--seed", 11]
    rust_refs, py_refs = [], []
    for flag, name in refs.items():
        clip = WALK if name == "walk" else HOP
        rust_refs += [flag, clip]
        py_refs += [flag, references[name]]
    done = rust(*args, *common, *rust_refs, "-o", work / f"{case}.bvh", "--features-json", rust_json,
                "--quiet")
    assert done.returncode == 0, done.stderr
    done = python(*args, *common, *py_refs, "-o", py_json)
    assert done.returncode == 0, done.stderr
    mean, std = normalizer()
    a = (load(rust_json) - mean[:, None]) / std[:, None]
    b = (load(py_json) - mean[:, None]) / std[:, None]
    assert a.shape == b.shape
    assert np.abs(a).max() > 0.1, "outputs are trivially small"
    diff = float(np.abs(a - b).max())
    print(f"{case}: max abs diff {diff}")
    # Generation chains every network call, so it also checks that Python and Rust
    # onnxruntime give the same forward pass (the export contract asks for 1e-6).
    limit = 1e-6 if case.startswith("generate") else 1e-4
    assert diff <= limit, f"{case}: max |diff| {diff} in normalised units"


def run_fails(tmp_path, *args):
    """Runs sinmdm expecting failure; returns stderr; checks nothing was written to tmp_path/out."""
    out = tmp_path / "out"
    done = rust(*args)
    assert done.returncode != 0, done.stdout
    assert "panicked" not in done.stderr, done.stderr
    assert not out.exists() or not any(out.iterdir()), list(out.iterdir())
    return done.stderr


def test_bad_input_is_refused_with_a_clear_error(tmp_path):
    out = tmp_path / "out" / "x.bvh"
    err = run_fails(tmp_path, "generate", "-m", tmp_path / "nothing.onnx", "-o", out)
    assert "nothing.onnx' does not exist" in err

    model = onnx.load(str(MODEL))
    del model.metadata_props[:]
    bare = tmp_path / "bare.onnx"
    onnx.save(model, str(bare))
    err = run_fails(tmp_path, "info", bare)
    assert "has no sinmdm metadata" in err

    model = onnx.load(str(MODEL))
    for p in model.metadata_props:
        if p.key == "sinmdm.metadata":
            meta = json.loads(p.value)
            del meta["training"]["clip_sha256"]
            p.value = json.dumps(meta)
    broken = tmp_path / "broken.onnx"
    onnx.save(model, str(broken))
    err = run_fails(tmp_path, "info", broken)
    assert "missing field `clip_sha256`" in err

    model = onnx.load(str(MODEL))
    for p in model.metadata_props:
        if p.key == "sinmdm.schema":
            p.value = "3"
    future = tmp_path / "future.onnx"
    onnx.save(model, str(future))
    err = run_fails(tmp_path, "generate", "-m", future, "-o", out)
    assert "schema '3'; this runtime reads schemas 1 and 2" in err

    truncated = tmp_path / "truncated.onnx"
    truncated.write_bytes(MODEL.read_bytes()[:5000])
    err = run_fails(tmp_path, "info", truncated)
    assert "is not a loadable ONNX model" in err

    m = ["-m", MODEL, "-o", out]
    err = run_fails(tmp_path, "inbetween", *m, "--reference", WALK, "--keep", "0:60", "--keep", "50:100")
    assert "spans 0:60 and 50:100 overlap" in err
    err = run_fails(tmp_path, "inbetween", *m, "--reference", WALK, "--keep", "0:900")
    assert "span 0:900 reaches past the reference's 249 frames" in err
    err = run_fails(tmp_path, "compose", *m, "--reference", WALK, "--joints", "Tail")
    assert "joint 'Tail' is not in the model's skeleton" in err
    err = run_fails(tmp_path, "inbetween", *m, "--reference", FOX, "--keep", "0:10")
    assert "skeleton differs from the model's" in err
    err = run_fails(tmp_path, "generate", *m, "--frames", 0)
    assert "a sample of 0 frames is not possible" in err
    err = run_fails(tmp_path, "generate", *m, "--frames", 5_000_000)
    assert "the limit is" in err
    err = run_fails(tmp_path, "generate", *m, "--count", 0)
    assert "--count must be between 1" in err
    err = run_fails(tmp_path, "generate", *m, "--steps", "many")
    assert "--steps must be a whole number" in err

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    err = run_fails(tmp_path, "generate", "-m", MODEL, "-o", blocker / "x.bvh", "--steps", 5)
    assert "cannot create output folder" in err
    assert blocker.read_text() == ""


def test_outputs_are_bvh_files_of_the_model_skeleton(tmp_path):
    import bvhio

    out = tmp_path / "crowd.bvh"
    done = rust("generate", "-m", MODEL, "-o", out, "--count", 3, "--seconds", 2, "--steps", 10, "--quiet")
    assert done.returncode == 0, done.stderr
    files = sorted(tmp_path.glob("crowd_*.bvh"))
    assert [f.name for f in files] == ["crowd_000.bvh", "crowd_001.bvh", "crowd_002.bvh"]
    source = bvhio.readAsBvh(str(WALK))
    for f in files:
        clip = bvhio.readAsBvh(str(f))
        assert len(clip.Root.layout()) == len(source.Root.layout())
        assert [j.Name for j, _, _ in clip.Root.layout()] == [j.Name for j, _, _ in source.Root.layout()]
        assert clip.FrameCount == 60
        assert abs(clip.FrameTime - 1 / 30) < 1e-6


@pytest.mark.parametrize("order,root", [("reference", "kept"), ("shuffled", "free")])
def test_rust_and_python_agree_on_a_dance(order, root, references):
    """`sinmdm dance` records the beats it used (--beats-out); the Python reference, given the
    same beats in frames, places the same keyframes and makes the same features, bit for bit."""
    work = references["work"]
    case = f"dance-{order}-{root}"
    rust_json, py_json, used = (work / f"{case}-rust.json", work / f"{case}-python.json",
                                work / f"{case}-beats.json")
    common = ["-m", MODEL, "--seed", 5, "--steps", 15, "--count", 2]
    dance = ["--order", order, "--root", root, "--hold", 2, "--ramp", 2]
    done = rust("dance", *common, *dance, "--reference", WALK, "--bpm", 100, "--offset", 0.3,
                "--seconds", 8, "--beats-out", used, "-o", work / f"{case}.bvh", "--features-json",
                rust_json, "--quiet")
    assert done.returncode == 0, done.stderr
    beats = json.loads(used.read_text())
    assert len(beats["keyframes"]) >= 6
    done = python("dance", *common, *dance, "--reference", references["walk"],
                  "--reference-beats", ",".join(map(str, beats["reference_beats"])),
                  "--target-beats", ",".join(map(str, beats["music_beats"])),
                  "--frames", beats["frames"], "-o", py_json)
    assert done.returncode == 0, done.stderr
    a, b = load(rust_json), load(py_json)
    assert a.shape == b.shape == (2, a.shape[1], beats["frames"])
    diff = float(np.abs(a - b).max())
    print(f"{case}: max abs diff {diff}")
    assert diff == 0.0, f"{case}: max |diff| {diff}"

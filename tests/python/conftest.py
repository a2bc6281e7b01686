"""Shared fixtures: the project root, the release binaries (built fresh) and the clips to check."""

import json
import pathlib
import re
import subprocess

import bvhio
import numpy as np
import pytest
import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]
SINMDM = ROOT / "target" / "release" / "sinmdm"
TRAIN = ROOT / "target" / "release" / "sinmdm-train"
EXPORT = ROOT / "target" / "release" / "sinmdm-export"
SHIPPED_CLIPS = ["fox_survey_khronos.bvh", "human_dance_rokoko_jesse.bvh",
                 "human_hop_cmu_131_03.bvh", "human_walk_cmu_131_01.bvh"]


def tiny_config(steps):
    """configs/tiny.yaml with its training steps set to `steps` (an error if the file no longer
    says `steps: 300`, so a test cannot silently train for the full length)."""
    text = (ROOT / "configs" / "tiny.yaml").read_text()
    assert "steps: 300" in text, "configs/tiny.yaml no longer trains 300 steps; update the tests"
    return text.replace("steps: 300", f"steps: {steps}")


def encoded_clip(clip, tmp_path, run_sinmdm, data_extra=""):
    """The clip's features as `sinmdm encode` writes them (JSON: fps, columns, samples), in the
    layout of a one-step model of configs/tiny.yaml trained on it (only its layout is used);
    `data_extra` adds lines to the config's `data` section."""
    config = tmp_path / "one_step.yaml"
    config.write_text(tiny_config(1) + data_extra)
    model = tmp_path / "layout.onnx"
    subprocess.run([str(TRAIN), str(clip), "--config", str(config), "--out", str(tmp_path / "run"),
                    "--export", str(model)], check=True, capture_output=True)
    features = tmp_path / "features.json"
    run_sinmdm("encode", clip, "-m", model, "-o", features)
    return json.loads(features.read_text())


def rust_constant(name):
    """A number of the clip rule as train/src/choose/clip_rule/ defines it (`pub const NAME: T = V;`),
    read from the source so that it lives in one place."""
    for path in sorted((ROOT / "train" / "src" / "choose" / "clip_rule").glob("*.rs")):
        found = re.search(rf"pub const {name}: \w+ = ([0-9_.]+);", path.read_text())
        if found:
            value = found.group(1).replace("_", "")
            return float(value) if "." in value else int(value)
    raise AssertionError(f"train/src/choose/clip_rule/ defines no {name}")


def floored_std(x, floor):
    """Each row's population std over frames, floored at `floor` times their mean (never under
    f32's smallest normal), as training normalises a clip (SPEC section 2)."""
    std = np.asarray(x, dtype=np.float64).std(axis=1)
    return np.maximum(std, max(std.mean() * floor, np.finfo(np.float32).tiny))


def default_config(section, key):
    """A value of configs/default.yaml (read, not restated)."""
    return yaml.safe_load((ROOT / "configs" / "default.yaml").read_text())[section][key]


def clips():
    """The shipped clips, plus every clip of the shared data folder beside the checkout."""
    shipped = sorted((ROOT / "tests" / "data" / "bvh").glob("*.bvh"))
    names = {p.name for p in shipped}
    missing = [n for n in SHIPPED_CLIPS if n not in names]
    assert not missing, f"tests/data/bvh lacks {missing}: a test over the clips would check nothing"
    shared = sorted((ROOT.parent / "shared" / "data" / "bvh").glob("*.bvh"))
    return shipped + [p for p in shared if p.name not in names]


@pytest.fixture(scope="session", autouse=True)
def release_build():
    """Builds the workspace in release before any test, so no test skips for a missing binary
    or runs a stale one (cargo does nothing when the binaries are up to date)."""
    subprocess.run(["cargo", "build", "--release", "--workspace", "--quiet"], cwd=ROOT, check=True)
    for exe in (SINMDM, TRAIN, EXPORT):
        assert exe.is_file(), f"{exe} is missing after the release build"


@pytest.fixture(scope="session")
def sinmdm():
    """Runs the release `sinmdm` binary and returns its standard output."""

    def run(*args):
        done = subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run


def bvhio_joint_positions(path):
    """Global joint positions [frames, joints, 3] and joint names, as bvhio computes them."""
    root = bvhio.readAsHierarchy(str(path))
    layout = root.layout()
    frames = []
    for frame in range(len(root.Keyframes)):
        root.loadPose(frame)
        frames.append([list(joint.PositionWorld) for joint, _, _ in layout])
    return np.asarray(frames, dtype=np.float64), [joint.Name for joint, _, _ in layout]

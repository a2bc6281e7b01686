"""The shipped models and the README's main command, checked from the outside: every model in
onnx-models/ has a card and metadata that match its clip, and scripts/demo.sh writes BVH files
that an independent reader (bvhio) parses, with the clip's skeleton and frame rate."""

import json
import re
import subprocess

import bvhio
import numpy as np
import onnx
import pytest
import yaml

from conftest import ROOT, SINMDM

MODELS = sorted((ROOT / "onnx-models").glob("*.onnx"))
CLIPS = ROOT / "tests" / "data" / "bvh"


def info(model):
    done = subprocess.run([str(SINMDM), "info", str(model), "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def joint_names(path):
    return [joint.Name for joint, _, _ in bvhio.readAsHierarchy(str(path)).layout()]


def test_the_expected_models_ship():
    names = {m.name for m in MODELS}
    assert {"human_walk_cmu.onnx", "human_hop_cmu.onnx", "fox_survey_khronos.onnx",
            "human_dance_rokoko.onnx"} <= names


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.stem)
def test_model_has_a_card_and_a_small_file(model):
    card = model.with_suffix(".md")
    assert card.exists(), f"{model.name} has no model card"
    text = card.read_text()
    meta = info(model)
    training = meta["training"]
    assert training["clip"] in text
    assert f"{training['steps']:,}".replace(",", " ") in text or str(training["steps"]) in text
    for row in ("coverage", "global diversity", "harmonic mean"):
        assert row in text, f"{card.name} has no eval table ({row})"
    assert model.stat().st_size < 8_000_000
    clip = CLIPS / training["clip"]
    assert clip.exists(), f"{training['clip']} is not shipped"


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.stem)
def test_the_card_names_the_floor_its_statistics_were_fitted_with(model):
    """The floor is a share of the mean spread before flooring: the smallest spread `v` is that
    share of it wherever a feature was floored, and the mean before flooring lies between the
    mean after it less the `k` floored rows' `v` each, and the mean after it. So the card's floor
    must lie in [v / mean, v / (mean - k v / n)] if any row sits at the minimum because of it, and
    under v / mean otherwise: a card cannot claim the new floor for a model trained under the
    old one, or the other way round."""
    text = model.with_suffix(".md").read_text()
    found = re.search(r"feature spread floor ([0-9.]+)", text)
    assert found, f"{model.stem}'s card does not name its feature spread floor"
    floor = float(found.group(1))
    props = {p.key: p.value for p in onnx.load(str(model), load_external_data=False).metadata_props}
    std = np.asarray(json.loads(props["sinmdm.metadata"])["normalizer"]["std"], dtype=np.float64)
    v, mean, n = std.min(), std.mean(), len(std)
    k = int(np.sum(std <= v * (1 + 1e-6)))
    low, high = v / mean, v / (mean - k * v / n)
    floored = low * (1 - 1e-5) <= floor <= high * (1 + 1e-5)
    assert floored or floor < low, (floor, low, high)
    assert high < 0.05 if floor < 0.05 else floored, (floor, low, high)
    flag = f"--std-floor {found.group(1)}" in text
    default = yaml.safe_load((ROOT / "configs" / "default.yaml").read_text())["data"]["std_floor"]
    assert flag == (floor != default), "the card's command must name a floor other than the default"


def test_main_command_writes_bvh_files_that_parse(tmp_path):
    out = tmp_path / "demo"
    done = subprocess.run([str(ROOT / "scripts" / "demo.sh"), str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    assert str(out) in done.stdout
    walk = CLIPS / "human_walk_cmu_131_01.bvh"
    fox = CLIPS / "fox_survey_khronos.bvh"
    dance = CLIPS / "human_dance_rokoko_jesse.bvh"
    expected = {
        "dance_1.bvh": dance, "dance_2.bvh": dance,
        "walk_new_000.bvh": walk, "walk_new_001.bvh": walk, "walk_new_002.bvh": walk,
        "walk_inbetween.bvh": walk, "walk_in_hop_style.bvh": walk,
        "fox_new_000.bvh": fox, "fox_new_001.bvh": fox, "fox_new_002.bvh": fox,
    }
    for name, clip in expected.items():
        path = out / name
        assert path.exists(), f"{name} missing; wrote {sorted(p.name for p in out.iterdir())}"
        assert joint_names(path) == joint_names(clip), name
        bvh = bvhio.readAsBvh(str(path))
        assert bvh.FrameCount > 30, name
        assert abs(bvh.FrameTime - 1 / 30) < 1e-6, name
    # New motions are twice the model's clip length (at the model's 30 fps).
    walk_frames = info(ROOT / "onnx-models" / "human_walk_cmu.onnx")["training"]["clip_frames"]
    assert bvhio.readAsBvh(str(out / "walk_new_000.bvh")).FrameCount == 2 * walk_frames
    assert (out / "walk_new.gif").read_bytes()[:6] == b"GIF89a"
    assert (out / "dance.gif").read_bytes()[:6] == b"GIF89a"
    # The dance lasts as long as the music (6.86 s at 30 fps) and keeps keyframes on its beats.
    used = json.loads((out / "dance_beats_1.json").read_text())
    assert bvhio.readAsBvh(str(out / "dance_1.bvh")).FrameCount == used["frames"] == 206
    assert len(used["keyframes"]) >= 6
    assert (out / "amen_click.wav").read_bytes()[:4] == b"RIFF"

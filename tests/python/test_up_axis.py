"""Z-up clips as they come: re-oriented copies checked with an independent reader (bvhio), a
round trip in the copy's own Z-up frame, and training, info, every task and eval on a Z-up clip.
"""

import json
import subprocess

import numpy as np
import pytest

from conftest import ROOT, TRAIN, bvhio_joint_positions, clips, tiny_config

WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"
# Canonical Y-up to Z-up: (x, y, z) -> (x, -z, y).
Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def bvhio_positions(path):
    """Global joint positions [frames, joints, 3], as bvhio computes them."""
    return bvhio_joint_positions(path)[0]


def extent(positions, axis):
    """Mean over frames of the joints' extent along one axis."""
    return float(np.mean(positions[:, :, axis].max(axis=1) - positions[:, :, axis].min(axis=1)))


# Clips captured Z-up (the shared zombie walk); every other clip is Y-up.
Z_UP_CLIPS = {"human_zombie_walk_fair.bvh"}


@pytest.mark.parametrize("clip", clips(), ids=lambda p: p.stem)
def test_z_up_copy_is_detected_and_round_trips_in_its_own_frame(clip, tmp_path, sinmdm):
    if clip.name in Z_UP_CLIPS:
        # Start from its Y-up twin, so that the copy below is a known turn of the original.
        yup = tmp_path / "yup.bvh"
        sinmdm("reorient", clip, "--to", "y", "-o", yup)
        clip = yup
    zup = tmp_path / "zup.bvh"
    sinmdm("reorient", clip, "--to", "z", "-o", zup)
    original = bvhio_positions(clip)
    copy = bvhio_positions(zup)
    height = extent(original, 1)
    # The copy is the original turned by the Z-up rotation, as bvhio reads both files.
    assert np.abs(copy - original @ Z_UP.T).max() <= 1e-4 * height
    assert abs(extent(copy, 2) - height) <= 1e-4 * height

    report = sinmdm("inspect", zup)
    up_line = next(line for line in report.splitlines() if line.startswith("up "))
    assert "+Z (sure" in up_line, up_line

    written = tmp_path / "roundtrip.bvh"
    sinmdm("inspect", zup, "--roundtrip", written)
    back = bvhio_positions(written)
    assert back.shape == copy.shape
    assert np.abs(back - copy).max() <= 1e-4 * height


def test_one_frame_is_reported_as_unsure(tmp_path, sinmdm):
    lines = WALK.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Frame Time"))
    one = lines[: start + 2]
    one[start - 1] = "Frames: 1"
    path = tmp_path / "one_frame.bvh"
    path.write_text("\n".join(one) + "\n")
    report = sinmdm("inspect", path)
    assert "UNSURE" in report and "only 1 frame" in report, report
    given = sinmdm("inspect", path, "--up", "y")
    assert "given with --up" in given


def test_training_and_every_task_on_a_z_up_clip(tmp_path, sinmdm):
    zup = tmp_path / "walk_zup.bvh"
    sinmdm("reorient", WALK, "--to", "z", "-o", zup)
    config = tmp_path / "tiny.yaml"
    config.write_text(tiny_config(20))
    model = tmp_path / "zup.onnx"
    done = subprocess.run([TRAIN, zup, "--config", config, "--out", tmp_path / "run",
                           "--export", model, "--threads", "2"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "up axis +Z (sure" in done.stderr, done.stderr

    assert "up axis      +Z" in sinmdm("info", model)
    metadata = json.loads(sinmdm("info", model, "--json"))
    assert metadata["layout"]["up"] == "+Z"

    out = tmp_path / "out"
    out.mkdir()
    common = ["-m", model, "--steps", "5", "--quiet"]
    sinmdm("generate", *common, "-o", out / "gen.bvh", "--frames", "120")
    sinmdm("inbetween", *common, "--reference", zup, "--keep", "0:60", "--keep", "150:",
           "-o", out / "ib.bvh")
    sinmdm("expand", *common, "--reference", zup, "--prefix", "30", "-o", out / "ex.bvh")
    sinmdm("compose", *common, "--reference", zup, "--part", "LeftHip", "--root",
           "-o", out / "co.bvh")
    sinmdm("harmonize", *common, "--content", zup, "-o", out / "ha.bvh")
    # A Y-up reference is turned into the model's Z-up convention.
    sinmdm("inbetween", *common, "--reference", WALK, "--keep", "0:60", "-o", out / "ib_y.bvh")
    report = sinmdm("eval", "-m", model, "--clip", zup, "--samples", "2", "--steps", "5",
                    "--quiet")
    assert "coverage" in report.lower()

    height = extent(bvhio_positions(zup), 2)
    for name in ["gen", "ib", "ex", "co", "ha", "ib_y"]:
        positions = bvhio_positions(out / f"{name}.bvh")
        # The files are Z-up like the clip: the figure stands along Z, about as tall as the clip.
        assert extent(positions, 2) > 0.5 * height, name
        assert extent(positions, 1) < extent(positions, 2) + 0.5 * height, name
    # In-betweening keeps the reference's first frames exactly, in the reference's own frame.
    kept = bvhio_positions(out / "ib.bvh")[:40]
    assert np.abs(kept - bvhio_positions(zup)[:40 * 4:4][: len(kept)]).max() < 1e-2 * height

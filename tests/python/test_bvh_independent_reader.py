"""An independent BVH reader (bvhio) agrees with ours on the files we write.

For every clip: encode to features and decode back to BVH at the clip's own frame rate
(`sinmdm inspect --roundtrip`), then load the written file with bvhio and compare its global
joint positions with (a) our forward kinematics of the written file and (b) bvhio's own reading
of the original clip. Both must agree within 1e-4 x skeleton height in every frame.
"""

import json

import numpy as np
import pytest

from conftest import bvhio_joint_positions as bvhio_positions, clips


def skeleton_height(positions):
    """Mean over frames of the vertical extent of the joints."""
    return float(np.mean(positions[:, :, 1].max(axis=1) - positions[:, :, 1].min(axis=1)))


@pytest.mark.parametrize("clip", clips(), ids=lambda p: p.stem)
def test_written_bvh_matches_bvhio(clip, tmp_path, sinmdm):
    written = tmp_path / "roundtrip.bvh"
    ours_json = tmp_path / "ours.json"
    sinmdm("inspect", clip, "--roundtrip", written)
    sinmdm("inspect", written, "--positions", ours_json)
    ours = json.loads(ours_json.read_text())
    ours_positions = np.asarray(ours["positions"], dtype=np.float64)

    theirs, names = bvhio_positions(written)
    original, original_names = bvhio_positions(clip)
    assert names == ours["joints"] == original_names
    assert theirs.shape == ours_positions.shape == original.shape

    height = skeleton_height(original)
    tolerance = 1e-4 * height
    assert np.abs(theirs - ours_positions).max() <= tolerance
    assert np.abs(theirs - original).max() <= tolerance

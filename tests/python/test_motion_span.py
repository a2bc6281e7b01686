"""The trainer's motion span (how long a clip's features stay correlated) and its wider-window hint,
against the same measure computed with numpy from the features `sinmdm encode` writes."""

import math
import re
import subprocess

import numpy as np
import pytest
import yaml

from conftest import TRAIN, clips, encoded_clip, floored_std, tiny_config

# SPEC section 3: the input and output convolutions (k 3) and the two k3 convolutions of each of
# the three residual blocks reach 8 frames each side; each of the three QnA blocks (k - 1) / 2.
FIXED_HALF_WIDTH = 8
QNA_BLOCKS = 3


def receptive_field(window):
    return 2 * (FIXED_HALF_WIDTH + QNA_BLOCKS * (window - 1) // 2) + 1


def numpy_span(raw, fps, floor):
    """First lag (frames) at which the mean autocorrelation of the feature rows falls below zero:
    rows normalised as for training (population std floored at `floor` of the mean std), rows
    that then still vary standardised, lags searched up to half the clip and 10 s."""
    x = np.asarray(raw, dtype=np.float64)
    x = (x - x.mean(axis=1, keepdims=True)) / floored_std(x, floor)[:, None]
    var = x.var(axis=1)
    keep = var > 1e-12
    z = (x[keep] - x[keep].mean(axis=1, keepdims=True)) / np.sqrt(var[keep])[:, None]
    frames = z.shape[1]
    for lag in range(1, min(frames // 2, int(10 * fps)) + 1):
        if np.mean(np.sum(z[:, : frames - lag] * z[:, lag:], axis=1) / (frames - lag)) < 0:
            return lag
    return None


@pytest.mark.parametrize("clip", clips(), ids=lambda p: p.stem)
def test_motion_span_and_hint_match_numpy(clip, tmp_path, sinmdm):
    config = tmp_path / "one_step.yaml"
    doc = encoded_clip(clip, tmp_path, sinmdm)
    raw = np.asarray(doc["samples"][0], dtype=np.float64)
    assert raw.shape[0] == len(doc["columns"])
    fps = doc["fps"]
    floor = yaml.safe_load(tiny_config(1))["data"]["std_floor"]
    expected = numpy_span(raw, fps, floor)

    out = subprocess.run([str(TRAIN), str(clip), "--config", str(config), "--dry-run"],
                         check=True, capture_output=True, text=True).stdout
    span = re.search(r"motion span\s+([0-9.]+) s", out)
    if expected is None:
        assert span is None and "motion span     longer than" in out, out
        return
    assert span, out
    assert abs(float(span.group(1)) - expected / fps) < 0.006, (span.group(1), expected / fps)

    # The hint names the narrowest window whose field spans half the span, when wider than 3.
    wanted = math.ceil(expected / 2)
    window = 3
    while receptive_field(window) < wanted:
        window += 2
    if window > 3:
        assert f"--window {window} (" in out, out
    else:
        assert "hint" not in out, out

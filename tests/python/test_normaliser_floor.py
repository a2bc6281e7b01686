"""The statistics a trained model carries are the clip's per-feature mean and population std, the
std floored at `data.std_floor` times the mean std (SPEC section 2, *Normalisation*), against the
same computed with numpy from the features `sinmdm encode` writes; `--std-floor` sets the floor."""

import json
import subprocess

import numpy as np
import onnx
import yaml

from conftest import ROOT, TRAIN, default_config, encoded_clip, floored_std, tiny_config

FOX = ROOT / "tests" / "data" / "bvh" / "fox_survey_khronos.bvh"


def model_statistics(path):
    props = {p.key: p.value for p in onnx.load(str(path)).metadata_props}
    meta = json.loads(props["sinmdm.metadata"])["normalizer"]
    return np.asarray(meta["mean"], dtype=np.float64), np.asarray(meta["std"], dtype=np.float64)


def numpy_statistics(raw, floor):
    x = np.asarray(raw, dtype=np.float64)
    return x.mean(axis=1), floored_std(x, floor)


def test_statistics_follow_the_configured_floor_and_the_flag(tmp_path, sinmdm):
    doc = encoded_clip(FOX, tmp_path, sinmdm)
    raw = doc["samples"][0]
    floor = yaml.safe_load(tiny_config(1))["data"]["std_floor"]
    assert floor == default_config("data", "std_floor") == 0.05

    mean, std = model_statistics(tmp_path / "layout.onnx")
    want_mean, want_std = numpy_statistics(raw, floor)
    assert np.allclose(mean, want_mean, rtol=1e-5, atol=1e-6)
    assert np.allclose(std, want_std, rtol=1e-4, atol=1e-7)

    # The fox's quiet features (a still joint's noise) are what the floor lifts: with the old
    # floor they keep their own tiny spread.
    old = tmp_path / "old.onnx"
    subprocess.run([str(TRAIN), str(FOX), "--config", str(tmp_path / "one_step.yaml"),
                    "--std-floor", "0.001", "--out", str(tmp_path / "old_run"),
                    "--export", str(old)], check=True, capture_output=True)
    _, old_std = model_statistics(old)
    _, want_old = numpy_statistics(raw, 0.001)
    assert np.allclose(old_std, want_old, rtol=1e-4, atol=1e-7)
    lifted = np.sum(std > old_std * 1.01)
    assert lifted >= 10, f"the floor lifts only {lifted} features"


def test_a_floor_outside_zero_to_one_is_refused(tmp_path):
    run = subprocess.run([str(TRAIN), str(FOX), "--std-floor", "1.5", "--out", str(tmp_path / "r"),
                          "--dry-run"], capture_output=True, text=True)
    assert run.returncode != 0
    assert "--std-floor 1.5" in run.stderr and "data.std_floor must be in [0, 1)" in run.stderr, \
        run.stderr

"""An exported model passes the ONNX checker, uses only allowed operators, carries our metadata,
and runs in Python onnxruntime with dynamic batch and length."""

import json
import subprocess

import numpy as np
import onnx
import onnxruntime as ort
import pytest

from conftest import ROOT, EXPORT, TRAIN, tiny_config



@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    work = tmp_path_factory.mktemp("export")
    config = work / "tiny.yaml"
    text = tiny_config(5)
    config.write_text(text)
    clip = ROOT / "tests" / "data" / "bvh" / "fox_survey_khronos.bvh"
    subprocess.run([TRAIN, clip, "--config", config, "--out", work / "run"], check=True,
                   capture_output=True)
    out = work / "model.onnx"
    subprocess.run([EXPORT, work / "run", "-o", out], check=True, capture_output=True)
    return out


def test_checker_operator_list_and_metadata(model_file):
    model = onnx.load(str(model_file))
    onnx.checker.check_model(model, full_check=True)
    assert model.ir_version <= 10
    assert [o.version for o in model.opset_import if o.domain in ("", "ai.onnx")] == [17]
    allowed = set((ROOT / "export" / "allowed_ops.txt").read_text().split())
    used = {n.op_type for n in model.graph.node}
    assert used <= allowed, used - allowed
    assert "GroupNormalization" not in used and "Einsum" not in used
    props = {p.key: p.value for p in model.metadata_props}
    assert props["sinmdm.schema"] == "1"
    meta = json.loads(props["sinmdm.metadata"])
    f = meta["network"]["features"]
    assert len(meta["normalizer"]["mean"]) == f
    assert meta["diffusion"] == {"steps": 1000, "schedule": "cosine", "prediction": "x0"}
    assert meta["network"]["receptive_field"] == 23
    assert meta["training"]["clip"] == "fox_survey_khronos.bvh"
    assert len(meta["training"]["clip_sha256"]) == 64
    assert meta["layout"]["skeleton"]["joints"][0]["name"]


def test_runs_with_dynamic_batch_and_length(model_file):
    session = ort.InferenceSession(str(model_file), providers=["CPUExecutionProvider"])
    f = session.get_inputs()[0].shape[1]
    for b, n in [(1, 23), (3, 157)]:
        x = np.random.default_rng(0).standard_normal((b, f, n)).astype(np.float32)
        t = np.arange(b, dtype=np.int64) * 300
        (x0,) = session.run(["x0"], {"x_t": x, "t": t})
        assert x0.shape == (b, f, n)
        assert np.isfinite(x0).all()


def test_train_export_flag_and_info(tmp_path):
    """`sinmdm-train --export` writes the model at the end of training; `sinmdm info` reads it."""
    config = tmp_path / "tiny.yaml"
    config.write_text(tiny_config(3))
    clip = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"
    out = tmp_path / "models" / "walk.onnx"
    subprocess.run([TRAIN, clip, "--config", config, "--out", tmp_path / "run", "--export", out],
                   check=True, capture_output=True)
    onnx.checker.check_model(onnx.load(str(out)), full_check=True)
    info = subprocess.run([ROOT / "target" / "release" / "sinmdm", "info", out],
                          capture_output=True, text=True, check=True).stdout
    assert "QnA-UNet, 191 features, 32 channels, 4 heads, window 3, receptive field 23 frames" in info
    assert "trained on   human_walk_cmu_131_01.bvh (249 frames" in info
    assert "training     3 steps" in info

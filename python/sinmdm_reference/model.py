"""A trained model file in onnxruntime, with its sinmdm metadata (as runtime/src/model.rs)."""

import json
import os

import numpy as np
import onnxruntime as ort

SCHEMA_KEY = "sinmdm.schema"
SCHEMA_VERSION = 2
# Schema 2 adds the heading-relative root (layout.root.heading); a model without it is schema 1.
SCHEMA_VERSIONS_READ = ("1", "2")
METADATA_KEY = "sinmdm.metadata"


class ModelError(Exception):
    """A model file that cannot be used."""


class Model:
    """The denoiser session and the metadata dictionary.

    As the runtime (SPEC section 6, the same bits on every machine): onnxruntime runs on one
    intra-op thread and each sample of a batch is its own call, so a sample's values depend
    neither on the machine's cores nor on its place in the batch."""

    def __init__(self, path):
        if not os.path.exists(path):
            raise ModelError(f"model file '{path}' does not exist")
        options = ort.SessionOptions()
        options.intra_op_num_threads = 1
        options.inter_op_num_threads = 1
        options.add_session_config_entry("session.intra_op.allow_spinning", "0")
        options.add_session_config_entry("session.inter_op.allow_spinning", "0")
        try:
            self.session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        except Exception as e:  # onnxruntime raises several types
            raise ModelError(f"'{path}' is not a loadable ONNX model: {e}") from e
        props = self.session.get_modelmeta().custom_metadata_map
        if SCHEMA_KEY not in props:
            raise ModelError(f"'{path}' has no sinmdm metadata (no '{SCHEMA_KEY}' entry)")
        if props[SCHEMA_KEY].strip() not in SCHEMA_VERSIONS_READ:
            raise ModelError(
                f"'{path}' carries schema '{props[SCHEMA_KEY]}', expected one of {', '.join(SCHEMA_VERSIONS_READ)}"
            )
        self.metadata = json.loads(props[METADATA_KEY])
        self.path = path
        self.features = self.metadata["network"]["features"]
        self.mean = np.asarray(self.metadata["normalizer"]["mean"], dtype=np.float32)
        self.std = np.asarray(self.metadata["normalizer"]["std"], dtype=np.float32)

    @property
    def layout(self):
        return self.metadata["layout"]

    def denoise(self, x_t, t):
        """x_t float32 [B, F, N], t int64 [B] -> predicted x0 float32 [B, F, N], one call per
        sample."""
        x_t = np.ascontiguousarray(x_t, dtype=np.float32)
        t = np.asarray(t, dtype=np.int64)
        out = np.empty_like(x_t)
        for b in range(x_t.shape[0]):
            (out[b : b + 1],) = self.session.run(["x0"], {"x_t": x_t[b : b + 1], "t": t[b : b + 1]})
        return out

    def normalize(self, raw):
        """(x - mean) / std per feature row of raw [F, N], in float32."""
        return (raw.astype(np.float32) - self.mean[:, None]) / self.std[:, None]

    def denormalize(self, x):
        """x * std + mean per feature row of [..., F, N], in float32."""
        return x * self.std[:, None] + self.mean[:, None]

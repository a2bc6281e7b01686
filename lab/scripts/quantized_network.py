"""What onnxruntime's 8-bit kernels buy on a shipped model: one call of one sample on one thread
with the fp32 graph against copies quantized by onnxruntime's own tools, and how far each copy's
clean prediction lands from the fp32 one.

Usage (from the repository root): .venv/bin/python lab/scripts/quantized_network.py MODEL.onnx
[FRAMES] [REPEATS]

The copies: dynamic quantization (weights int8, activations quantized per call) of the matrix
products only, and of the matrix products and convolutions. Each is timed on the same noisy
inputs at three diffusion steps (t = 999, 500, 20), median of REPEATS, and compared with the
fp32 prediction as the error relative to the prediction's spread (RMS of the difference over
the RMS of the fp32 prediction). The metadata the runtime reads is copied into each file, so
`sinmdm` can open them for a stream's fidelity.
"""

import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
from onnxruntime.quantization import QuantType, quantize_dynamic


def session(path: str) -> ort.InferenceSession:
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    return ort.InferenceSession(path, options, providers=["CPUExecutionProvider"])


def with_metadata(source: onnx.ModelProto, path: Path) -> None:
    """Copies the source's metadata properties into the model at `path`."""
    model = onnx.load(str(path))
    del model.metadata_props[:]
    model.metadata_props.extend(source.metadata_props)
    onnx.save(model, str(path))


def ops(path: Path) -> str:
    model = onnx.load(str(path))
    counts: dict[str, int] = {}
    for node in model.graph.node:
        counts[node.op_type] = counts.get(node.op_type, 0) + 1
    top = sorted(counts.items(), key=lambda kv: -kv[1])[:6]
    return ", ".join(f"{k} {v}" for k, v in top)


def main() -> None:
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = Path(sys.argv[1])
    source = onnx.load(str(path))
    fp32 = session(str(path))
    meta = json.loads(fp32.get_modelmeta().custom_metadata_map["sinmdm.metadata"])
    features = meta["network"]["features"]
    frames = int(sys.argv[2]) if len(sys.argv) > 2 else meta["training"]["clip_frames"]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    out_dir = Path(tempfile.mkdtemp(prefix="quantized-"))
    copies = {}
    for name, op_types in [("int8 MatMul", ["MatMul", "Gemm"]), ("int8 MatMul+Conv", ["MatMul", "Gemm", "Conv"])]:
        target = out_dir / (name.replace(" ", "_").replace("+", "_") + ".onnx")
        quantize_dynamic(str(path), str(target), op_types_to_quantize=op_types, weight_type=QuantType.QInt8)
        with_metadata(source, target)
        copies[name] = target
    rng = np.random.default_rng(0)
    x = rng.standard_normal((1, features, frames)).astype(np.float32)
    print(f"{path}: F {features}, {frames} frames, one sample a call, one thread, median of {repeats}")
    print(f"fp32 graph: {ops(path)}")
    for name, target in copies.items():
        print(f"{name} ({target}): {ops(target)}")
    print("| graph | ms per call | x fp32 | prediction error / spread at t=999, 500, 20 |")
    print("|---|---|---|---|")
    base_ms = None
    for name, target in [("fp32", path), *copies.items()]:
        s = session(str(target))
        times, errors = [], []
        for t in [999, 500, 20]:
            feed = {"x_t": x, "t": np.array([t], dtype=np.int64)}
            want = fp32.run(["x0"], feed)[0]
            got = s.run(["x0"], feed)[0]
            spread = float(np.sqrt(np.mean(want.astype(np.float64) ** 2)))
            errors.append(float(np.sqrt(np.mean((got.astype(np.float64) - want) ** 2))) / max(spread, 1e-12))
            for _ in range(repeats):
                begun = time.perf_counter()
                s.run(["x0"], feed)
                times.append(time.perf_counter() - begun)
        ms = 1000 * statistics.median(times)
        base_ms = base_ms or ms
        print(f"| {name} | {ms:.2f} | {base_ms / ms:.2f} | {', '.join(f'{e:.3f}' for e in errors)} |")


if __name__ == "__main__":
    main()

"""What one network call of many samples costs against as many calls of one sample, on one
thread, and whether each row of the batched call is the same bits as that sample alone.

Usage (from the repository root): .venv/bin/python lab/scripts/batched_network.py MODEL.onnx
[FRAMES] [REPEATS]

The runtime's `Model` runs a batch one sample per onnxruntime call (spread over its threads),
so a crowd of streams stepped together costs, per character, what each stream costs alone. This
measures what a single call over the whole batch would buy, on one intra-op thread, for batches
of 1 to 64 samples of FRAMES frames (default: the model's training clip), median of REPEATS.
"""

import json
import statistics
import sys
import time

import numpy as np
import onnxruntime as ort


def session(path: str) -> ort.InferenceSession:
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    return ort.InferenceSession(path, options, providers=["CPUExecutionProvider"])


def main() -> None:
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    s = session(path)
    meta = json.loads(s.get_modelmeta().custom_metadata_map["sinmdm.metadata"])
    features = meta["network"]["features"]
    frames = int(sys.argv[2]) if len(sys.argv) > 2 else meta["training"]["clip_frames"]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    rng = np.random.default_rng(0)
    print(f"{path}: F {features}, {frames} frames, one thread, median of {repeats}")
    print("| samples | one call of all: ms per sample | a call per sample: ms per sample | ratio | rows equal to alone |")
    print("|---|---|---|---|---|")
    for batch in [1, 2, 4, 8, 16, 32, 64]:
        x = rng.standard_normal((batch, features, frames)).astype(np.float32)
        t = rng.integers(0, 1000, size=batch).astype(np.int64)
        together, apart = [], []
        for _ in range(repeats):
            begun = time.perf_counter()
            out = s.run(["x0"], {"x_t": x, "t": t})[0]
            together.append(time.perf_counter() - begun)
            begun = time.perf_counter()
            alone = [s.run(["x0"], {"x_t": x[i : i + 1], "t": t[i : i + 1]})[0] for i in range(batch)]
            apart.append(time.perf_counter() - begun)
        equal = all(np.array_equal(out[i : i + 1], alone[i]) for i in range(batch))
        a = 1000 * statistics.median(together) / batch
        b = 1000 * statistics.median(apart) / batch
        print(f"| {batch} | {a:.2f} | {b:.2f} | {b / a:.2f} | {'yes' if equal else 'no'} |")


if __name__ == "__main__":
    main()

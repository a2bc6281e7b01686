#!/usr/bin/env python3
"""Where a denoiser call's time goes, against the machine's GEMM roofline, in one run:

    .venv/bin/python lab/scripts/profile_network.py [MODEL.onnx] [FRAMES] [CALLS] [ROUNDS]

1. The arithmetic of one call of one sample: every Conv and MatMul's multiply-adds, from the
   graph's shapes at FRAMES frames (onnx shape inference), as GFLOP (2 per multiply-add).
2. onnxruntime's own profiler over CALLS calls as the runtime makes them (one sample, one
   intra-op thread, graph optimisation `all`): the share of each operator type in the kernels'
   time, and the time outside the kernels (the session's own overhead per call).
3. The roofline: an onnxruntime MatMul of the network's largest GEMM shape (C x 3C by 3C x N,
   summed to the same FLOP count) on one thread, measured in the same run, and numpy's sgemm.
4. The ratio: achieved network GFLOP/s over the GEMM's; the elementwise operators' share is the
   part the GEMM rate cannot speed up.
5. The whole process: `sinmdm generate --count 20 --frames FRAMES` (default sampling, planted
   feet, BVH written) ROUNDS times (default 3), against the time of its arithmetic
   (20 x steps x the GFLOP above) at the GEMM rate on every core, measured in the same run.
"""

import collections
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import onnx
import onnxruntime as ort
from onnx import helper, shape_inference

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def session(path_or_bytes, profile_dir=None, threads=1):
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads
    options.inter_op_num_threads = 1
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    options.add_session_config_entry("session.intra_op.allow_spinning", "0")
    if profile_dir:
        options.enable_profiling = True
        options.profile_file_prefix = os.path.join(profile_dir, "sinmdm")
    return ort.InferenceSession(path_or_bytes, options, providers=["CPUExecutionProvider"])


def arithmetic(model, features, frames):
    """Multiply-adds of the Conv and MatMul nodes of one sample at `frames` frames."""
    fixed = onnx.ModelProto()
    fixed.CopyFrom(model)
    for value in fixed.graph.input:
        dims = value.type.tensor_type.shape.dim
        if value.name == "x_t":
            dims[0].dim_value, dims[2].dim_value = 1, frames
        elif value.name == "t":
            dims[0].dim_value = 1
    inferred = shape_inference.infer_shapes(fixed, data_prop=True)
    shapes = {}
    for value in list(inferred.graph.value_info) + list(inferred.graph.input) + list(inferred.graph.output):
        shapes[value.name] = [d.dim_value for d in value.type.tensor_type.shape.dim]
    for init in inferred.graph.initializer:
        shapes[init.name] = list(init.dims)
    macs = collections.Counter()
    unknown = 0
    for node in inferred.graph.node:
        if node.op_type == "Conv":
            out, w = shapes.get(node.output[0]), shapes.get(node.input[1])
            if not out or not w or 0 in out:
                unknown += 1
                continue
            # out [B, Cout, N], weight [Cout, Cin/groups, K]
            macs["Conv"] += int(np.prod(out)) * int(np.prod(w[1:]))
        elif node.op_type == "MatMul":
            a, b = shapes.get(node.input[0]), shapes.get(node.input[1])
            out = shapes.get(node.output[0])
            if not a or not out or 0 in out or 0 in a:
                unknown += 1
                continue
            macs["MatMul"] += int(np.prod(out)) * a[-1]
    return macs, unknown


def profile(path, features, frames, calls):
    with tempfile.TemporaryDirectory() as tmp:
        s = session(path, tmp)
        rng = np.random.default_rng(0)
        x = rng.standard_normal((1, features, frames)).astype(np.float32)
        t = np.array([500], dtype=np.int64)
        s.run(["x0"], {"x_t": x, "t": t})
        walls = []
        for _ in range(calls):
            start = time.perf_counter()
            s.run(["x0"], {"x_t": x, "t": t})
            walls.append(time.perf_counter() - start)
        trace = json.load(open(s.end_profiling()))
    kernels = collections.Counter()
    runs = []
    for event in trace:
        if event.get("cat") == "Node" and event["name"].endswith("_kernel_time"):
            kernels[event["args"]["op_name"]] += event["dur"]
        if event.get("cat") == "Session" and event["name"] == "model_run":
            runs.append(event["dur"])
    return kernels, runs, walls


def gemm_rate(c, n, repeats=30, threads=1):
    """GFLOP/s of an onnxruntime MatMul [C, 3C] x [3C, N] on `threads` threads, and numpy's (on
    its own threads)."""
    a = helper.make_tensor_value_info("a", onnx.TensorProto.FLOAT, [c, 3 * c])
    b = helper.make_tensor_value_info("b", onnx.TensorProto.FLOAT, [3 * c, n])
    y = helper.make_tensor_value_info("y", onnx.TensorProto.FLOAT, [c, n])
    graph = helper.make_graph([helper.make_node("MatMul", ["a", "b"], ["y"])], "gemm", [a, b], [y])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    s = session(model.SerializeToString(), threads=threads)
    rng = np.random.default_rng(1)
    av = rng.standard_normal((c, 3 * c)).astype(np.float32)
    bv = rng.standard_normal((3 * c, n)).astype(np.float32)
    s.run(None, {"a": av, "b": bv})
    flops = 2.0 * c * 3 * c * n
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        s.run(None, {"a": av, "b": bv})
        times.append(time.perf_counter() - start)
    np_times = []
    for _ in range(repeats):
        start = time.perf_counter()
        av @ bv
        np_times.append(time.perf_counter() - start)
    return flops / statistics.median(times) / 1e9, flops / statistics.median(np_times) / 1e9


def main(argv):
    path = argv[1] if len(argv) > 1 else os.path.join(REPO, "onnx-models", "human_walk_cmu.onnx")
    frames = int(argv[2]) if len(argv) > 2 else 498
    calls = int(argv[3]) if len(argv) > 3 else 50
    model = onnx.load(path)
    meta = {p.key: p.value for p in model.metadata_props}
    network = json.loads(meta["sinmdm.metadata"])["network"]
    features, channels = network["features"], network["channels"]
    macs, unknown = arithmetic(model, features, frames)
    gflop = 2.0 * sum(macs.values()) / 1e9
    kernels, runs, walls = profile(path, features, frames, calls)
    kernel_total = sum(kernels.values())
    wall = statistics.median(walls)
    ort_rate, numpy_rate = gemm_rate(channels, frames * 20)
    print(f"model {os.path.relpath(path, REPO)}: F {features}, C {channels}; one sample of {frames} frames")
    print(f"arithmetic per call: {gflop:.4f} GFLOP (Conv {2 * macs['Conv'] / 1e9:.4f}, "
          f"MatMul {2 * macs['MatMul'] / 1e9:.4f}; {unknown} nodes without static shapes)")
    print(f"call: {wall * 1e3:.2f} ms wall (median of {calls}), kernels {kernel_total / calls / 1e3:.2f} ms, "
          f"outside the kernels {(statistics.median(runs) - kernel_total / calls) / 1e3:.2f} ms")
    print("share of kernel time by operator:")
    for op, dur in kernels.most_common():
        print(f"  {op:<22} {100 * dur / kernel_total:5.1f} %  {dur / calls / 1e3:7.3f} ms/call")
    achieved = gflop / wall
    print(f"GEMM roofline (one thread, {channels}x{3 * channels} by {3 * channels}x{frames * 20}): "
          f"onnxruntime MatMul {ort_rate:.1f} GFLOP/s, numpy {numpy_rate:.1f} GFLOP/s")
    print(f"network: {achieved:.1f} GFLOP/s achieved = {ort_rate / achieved:.1f}x the GEMM time of its arithmetic")
    gemm_share = sum(kernels[op] for op in ("Conv", "FusedConv", "MatMul", "FusedMatMul")) / kernel_total
    print(f"time in Conv/MatMul kernels: {100 * gemm_share:.1f} %; the rest (normalisation, elementwise, "
          f"reshapes) is memory-bound work the GEMM rate does not bound")
    rounds = int(argv[4]) if len(argv) > 4 else 3
    sinmdm = os.path.join(REPO, "target", "release", "sinmdm")
    if rounds == 0 or not os.path.isfile(sinmdm):
        return
    cores = os.cpu_count() or 1
    all_cores, numpy_all = gemm_rate(channels, frames * 20, threads=cores)
    steps = 50
    total = 20 * steps * gflop
    whole = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(rounds):
            start = time.perf_counter()
            subprocess.run([sinmdm, "generate", "-m", path, "--count", "20", "--frames", str(frames), "--quiet",
                            "-o", os.path.join(tmp, "s.bvh")], check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            whole.append(time.perf_counter() - start)
    best = max(all_cores, numpy_all)
    print(f"20 samples x {frames} frames x {steps} steps, whole process: {statistics.median(whole):.2f} s "
          f"(median of {rounds}); arithmetic {total:.1f} GFLOP = {total / best:.2f} s at {best:.1f} GFLOP/s "
          f"(the faster of onnxruntime's MatMul on {cores} threads, {all_cores:.1f}, and numpy's, {numpy_all:.1f}): "
          f"{statistics.median(whole) / (total / best):.2f}x")


if __name__ == "__main__":
    main(sys.argv)

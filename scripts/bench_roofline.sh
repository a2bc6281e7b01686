#!/usr/bin/env bash
# Sampling against the machine's limit, in one run (pause any training: this machine has two
# cores, and the figures compare only side by side):
# 1. lab/scripts/profile_network.py: the network's arithmetic counted from the graph, onnxruntime's
#    profile of one call, a GEMM of the network's shape (the roofline), and the default crowd
#    (`sinmdm generate --count 20`) as a whole process against its arithmetic at that GEMM rate;
# 2. cargo bench --bench roofline: the runtime's 1 000-step single-sample loop against a bare
#    onnxruntime loop (one process: paired whole-loop rounds, and the two interleaved step by
#    step), a stream's 1-second chunks, and the crowd in
#    process.
# Usage: scripts/bench_roofline.sh [MODEL.onnx] [FRAMES] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-onnx-models/human_walk_cmu.onnx}
frames=${2:-498}
rounds=${3:-5}
cargo build --release -p sinmdm-cli --quiet
echo "== $(date -u +%Y-%m-%d) on $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "== the network against the GEMM roofline (lab/scripts/profile_network.py)"
.venv/bin/python lab/scripts/profile_network.py "$model" "$frames" 50 "$rounds"
echo "== the runtime's loops (cargo bench -p sinmdm --bench roofline)"
cargo bench -q -p sinmdm --bench roofline -- "$(realpath "$model")" "$frames" "$rounds" 2>/dev/null

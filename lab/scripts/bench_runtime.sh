#!/usr/bin/env bash
# Sampling benchmark at the paper's size: makes a C 256 model (paper.yaml, one training step,
# so the cost is the trained model's), prints its file size, then the Rust loop against bare
# onnxruntime calls for batch 1 and 16 (cargo bench), then the Python reference's full
# 1000-step sample. Usage: lab/scripts/bench_runtime.sh [FRAMES] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/../.."
frames=${1:-200}
threads=${2:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e 's/^  steps: 60000/  steps: 1/' -e 's/batch_size: 64/batch_size: 1/' \
    -e 's/checkpoint_every: [0-9]*/checkpoint_every: 1/' configs/paper.yaml > "$work/paper1.yaml"
target/release/sinmdm-train tests/data/bvh/human_walk_cmu_131_01.bvh --config "$work/paper1.yaml" \
    --out "$work/run" --export "$work/paper.onnx" >/dev/null 2>&1
cargo bench -q -p sinmdm --bench sampling -- "$work/paper.onnx" "$frames" "$threads" 2>/dev/null
start=$(date +%s.%N)
.venv/bin/python -m sinmdm_reference generate -m "$work/paper.onnx" --frames "$frames" \
    --steps all -o "$work/python.json" 2>/dev/null
end=$(date +%s.%N)
echo "Python reference (numpy + onnxruntime), 1 sample of 1000 steps: $(echo "$end - $start" | bc) s"

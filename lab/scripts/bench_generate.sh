#!/usr/bin/env bash
# Whole-process time of the default sampling: `sinmdm generate --count 20` of 498-frame samples
# (twice the walk clip) with the default sampler and steps, planted feet and BVH output
# included, ROUNDS times; prints every round, the median and the median per sample.
# Usage: lab/scripts/bench_generate.sh [MODEL.onnx] [ROUNDS] [extra sinmdm generate arguments...]
# Pause any training while this runs: this machine has two cores.
set -euo pipefail
cd "$(dirname "$0")/../.."
model=${1:-onnx-models/human_walk_cmu.onnx}
rounds=${2:-5}
shift $(( $# > 2 ? 2 : $# ))
sinmdm=target/release/sinmdm
[ -x "$sinmdm" ] || cargo build --release -p sinmdm-cli --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
times=()
for round in $(seq "$rounds"); do
  start=$(date +%s.%N)
  "$sinmdm" generate -m "$model" --count 20 --frames 498 --quiet -o "$work/sample.bvh" "$@" >/dev/null
  end=$(date +%s.%N)
  t=$(echo "$end - $start" | bc)
  times+=("$t")
  echo "round $round: $t s"
done
median=$(printf '%s\n' "${times[@]}" | sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}')
echo "median of $rounds: $median s for 20 samples, $(echo "scale=4; $median / 20" | bc) s per sample"

#!/usr/bin/env bash
# The main job on a shipped default: sets the project up if needed, then generates from the
# shipped walk model: three new walks of twice the clip's length, an in-between and an
# expansion of the clip, as BVH files (open them in Blender) in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p out
model=onnx-models/human_walk_cmu.onnx
clip=tests/data/bvh/human_walk_cmu_131_01.bvh
sinmdm=./target/release/sinmdm
"$sinmdm" info "$model" | sed -n '2p;9,10p'
"$sinmdm" generate -m "$model" --count 3 --seed 1 -o out/walk_new.bvh
"$sinmdm" inbetween -m "$model" --reference "$clip" --keep 0:3s --keep 5s: -o out/walk_inbetween.bvh
"$sinmdm" expand -m "$model" --reference "$clip" --prefix 2s --suffix 2s -o out/walk_expanded.bvh
echo
echo "demo: BVH files written to $(pwd)/out/"

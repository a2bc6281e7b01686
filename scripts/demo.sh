#!/usr/bin/env bash
# The main job on a shipped default: sets the project up if needed, then shows what the model
# sees of a shipped clip and checks the motion representation by a round trip, writing BVH files
# you can open in Blender into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p out
clip=tests/data/bvh/human_walk_cmu_131_01.bvh
./target/release/sinmdm inspect "$clip" --fps 30 --roundtrip out/walk_30fps_roundtrip.bvh
./target/release/sinmdm inspect tests/data/bvh/fox_survey_khronos.bvh --roundtrip out/fox_roundtrip.bvh \
  | grep -E '^(clip|frames|contacts|features|roundtrip)'
echo
echo "demo: BVH files written to $(pwd)/out/"

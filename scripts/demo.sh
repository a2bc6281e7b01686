#!/usr/bin/env bash
# The main job on the shipped models: builds the sinmdm command line and finds (or fetches) an
# onnxruntime for it if needed (scripts/setup.sh: not the tests' set-up, no root), then
#  - three new walks of twice the clip's length from the walk model (with a GIF of them),
#  - an in-between (the clip's first 3 s and its last part kept, the gap generated),
#  - a style transfer: the CMU walk in the style of the model trained on the CMU hop,
#  - three new fox motions from the fox model,
#  - two dances (seeds 1 and 2) to a CC0 breakbeat loop from the model of the Rokoko dance (with
#    a GIF, the beats each used, and the loop with a click on each beat the tracker found),
#  - two zombie walks steered round a circle of three heights' radius (the heading-relative
#    model), with how closely each followed it,
# as BVH files (they open in Blender with the clip's skeleton, units and frame rate),
#  - and a crowd of eight walks as ONE glTF file (walk_crowd.glb: one animation each, metres,
#    +Y up), which Godot, Blender, three.js and Unity's glTFast open as it is.
# Usage: scripts/demo.sh [OUT_DIR]   (default: out)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out}
scripts/setup.sh
mkdir -p "$out"
sinmdm=${CARGO_TARGET_DIR:-./target}/release/sinmdm
walk_model=onnx-models/human_walk_cmu.onnx
hop_model=onnx-models/human_hop_cmu.onnx
fox_model=onnx-models/fox_survey_khronos.onnx
dance_model=onnx-models/human_dance_rokoko.onnx
walk=tests/data/bvh/human_walk_cmu_131_01.bvh
dance=tests/data/bvh/human_dance_rokoko_jesse.bvh
music=tests/data/audio/loop_amen_full.wav
"$sinmdm" generate -m "$walk_model" --count 3 --seed 1 -o "$out/walk_new.bvh" --render "$out/walk_new.gif"
"$sinmdm" inbetween -m "$walk_model" --reference "$walk" --keep 0:3s --keep 5s: -o "$out/walk_inbetween.bvh"
"$sinmdm" harmonize -m "$hop_model" --content "$walk" -o "$out/walk_in_hop_style.bvh"
"$sinmdm" generate -m "$fox_model" --count 3 --seed 1 -o "$out/fox_new.bvh" --render "$out/fox_new.gif"
"$sinmdm" beats "$music" --click "$out/amen_click.wav"
for seed in 1 2; do
  "$sinmdm" dance -m "$dance_model" --reference "$dance" --music "$music" --seed "$seed" \
    -o "$out/dance_$seed.bvh" --beats-out "$out/dance_beats_$seed.json"
done
"$sinmdm" render "$out/dance_1.bvh" "$out/dance_2.bvh" -o "$out/dance.gif"
"$sinmdm" steer -m onnx-models/human_zombie_walk_fair.onnx --circle 3 --count 2 --seed 1 \
  -o "$out/zombie_circle.bvh" --report
# CMU's unit is unsure from the skeleton's height alone; it is 1/0.45 inch.
"$sinmdm" generate -m "$walk_model" --count 8 --seed 2 -o "$out/walk_crowd.glb" --unit-scale 0.056444
echo
echo "demo: BVH, GLB and GIF files written to $(cd "$out" && pwd)/"
ls "$out"

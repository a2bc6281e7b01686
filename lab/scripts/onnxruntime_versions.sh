#!/usr/bin/env bash
# Which onnxruntime releases the runtime works with, and whether they give the same bits: each
# release's shared library is fetched from the package registries (PyPI wheels from 1.19 on,
# which ship libonnxruntime.so; the npm package onnxruntime-node for older ones), then the same
# crowd is generated through each with ORT_DYLIB_PATH and compared byte for byte with the
# pinned release's. Linux x86-64. Usage: lab/scripts/onnxruntime_versions.sh [WORK_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/onnxruntime-versions}
mkdir -p "$work"
sinmdm=target/release/sinmdm
cargo build --release --quiet -p sinmdm-cli
generate() {
  ORT_DYLIB_PATH="$1" "$sinmdm" generate -m onnx-models/human_walk_cmu.onnx --count 3 --seconds 2 \
    --steps 6 --seed 4 -o "$work/out.bvh" --features-json "$2" --quiet 2>&1 | tail -n 1
}
pinned=$(ls .venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.1* | head -n 1)
generate "$pinned" "$work/pinned.json" >/dev/null
echo "pinned: $pinned"
for version in 1.16.3 1.17.0; do
  lib="$work/node-$version/libonnxruntime.so.$version"
  if [ ! -f "$lib" ]; then
    (cd "$work" && npm pack "onnxruntime-node@$version" --silent >/dev/null)
    mkdir -p "$work/node-$version"
    tar xzf "$work/onnxruntime-node-$version.tgz" -C "$work/node-$version" --strip-components=5 \
      "package/bin/napi-v3/linux/x64/libonnxruntime.so.$version"
  fi
  echo "$version: $(generate "$lib" "$work/$version.json")"
  cmp -s "$work/$version.json" "$work/pinned.json" && echo "$version: same bits as the pinned release"
done
for version in 1.19.2 1.20.1; do
  lib="$work/wheel-$version/libonnxruntime.so.$version"
  if [ ! -f "$lib" ]; then
    .venv/bin/pip download --quiet --no-deps --only-binary=:all: --python-version 3.11 \
      --platform manylinux_2_27_x86_64 --platform manylinux_2_28_x86_64 "onnxruntime==$version" -d "$work"
    mkdir -p "$work/wheel-$version"
    unzip -o -q -j "$work"/onnxruntime-"$version"-*.whl "onnxruntime/capi/libonnxruntime.so.$version" -d "$work/wheel-$version"
  fi
  echo "$version: $(generate "$lib" "$work/$version.json")"
  cmp -s "$work/$version.json" "$work/pinned.json" && echo "$version: same bits as the pinned release"
done

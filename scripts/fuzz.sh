#!/usr/bin/env bash
# Runs every file reader under libFuzzer for a time budget each, seeded with the test fixtures:
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]      (default 1800 s, every target)
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`). Each input may take
# at most 1 s and 512 MB of allocation (-timeout, -malloc_limit_mb); a crash, hang or
# allocation over the limit stops the target and leaves its input in fuzz/artifacts/TARGET/.
# The model target's inputs are whole networks that onnxruntime builds a session for (0.1-0.5 s
# each on a busy 2-core machine), so its run allows 5 s; after each run every input of the
# corpus is timed again, one by one, and the slowest is printed against the 1 s bound.
# Prints one line a target: runs, executions a second, corpus size, the slowest input, and the
# verdict.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-1800}"
shift || true
targets=("$@")
if [ "${#targets[@]}" -eq 0 ]; then
  targets=(bvh gltf fbx audio bone_map manifest model)
fi
# The model target loads onnxruntime as the command line does; the tests' wheel serves here.
if [ -z "${ORT_DYLIB_PATH:-}" ]; then
  for lib in .venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.*; do
    [ -f "$lib" ] && export ORT_DYLIB_PATH="$PWD/$lib"
  done
fi
command -v cargo-fuzz >/dev/null || { echo "fuzz: cargo-fuzz is needed: cargo install cargo-fuzz" >&2; exit 1; }

seed() {
  local target="$1" dir="fuzz/corpus/$1"
  mkdir -p "$dir"
  case "$target" in
    bvh) cp tests/data/gltf/*_2s.bvh tests/data/two_joints.bvh "$dir/" ;;
    gltf) cp tests/data/gltf/*.glb "$dir/" ;;
    fbx)
      cp tests/data/fbx/*.fbx "$dir/"
      for f in tests/data/fbx/*.fbx.gz; do gunzip -c "$f" > "$dir/$(basename "$f" .gz)"; done ;;
    audio) cp tests/data/audio/*.wav "$dir/" ;;
    bone_map) printf 'pelvis: Hips\nthigh_l: LeftHip\n"mixamorig:Spine": Chest\n' > "$dir/map.yaml" ;;
    manifest)
      printf 'clips:\n  - clip: %s\n    name: walk\n    fps: 30\n    contacts: [LeftToe]\n' \
        "$PWD/tests/data/gltf/human_walk_cmu_131_01_2s.bvh" > "$dir/library.yaml" ;;
    model) cp tests/data/models/walk_tiny.onnx "$dir/" ;;
  esac
}

cargo +nightly fuzz build -O
for target in "${targets[@]}"; do
  seed "$target"
  log="fuzz/artifacts/$target.log"
  mkdir -p fuzz/artifacts
  status=0
  timeout=1 max_len=1048576
  [ "$target" = model ] && timeout=5
  # The keyframe readers may sample up to MAX_SPARSE_TRANSFORMS from any file and one
  # transform per BYTES_PER_SPARSE_TRANSFORM bytes beyond: inputs up to 256 KB keep them at the
  # floor, whose time is the one the 1 s bound is for.
  case "$target" in gltf | fbx) max_len=262144 ;; esac
  cargo +nightly fuzz run -O "$target" "fuzz/corpus/$target" -- \
    -max_total_time="$seconds" -timeout="$timeout" -malloc_limit_mb=512 -rss_limit_mb=2048 \
    -max_len="$max_len" -print_final_stats=1 >"$log" 2>&1 || status=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  corpus=$(find "fuzz/corpus/$target" -type f | wc -l)
  # Every corpus input again, alone (a file argument runs it once): the slowest, in ms. Each
  # process first runs an empty input, so that loading a library (onnxruntime) is not counted.
  binary=fuzz/target/x86_64-unknown-linux-gnu/release/$target
  warm=$(mktemp)
  slowest=$(find "fuzz/corpus/$target" -type f -print0 | xargs -0 -n 200 "$binary" "$warm" 2>&1 |
    grep -v "^Executed $warm " | sed -n 's/^Executed \(.*\) in \([0-9]*\) ms$/\2 \1/p' |
    sort -n | tail -1)
  rm -f "$warm"
  slowest_ms=${slowest%% *}
  if [ "$status" -ne 0 ]; then verdict="FAILED (see $log and fuzz/artifacts/$target/)"
  elif [ "${slowest_ms:-0}" -gt 1000 ]; then verdict="SLOW: ${slowest#* } takes ${slowest_ms} ms"
  else verdict="no crash, no hang over 1 s, no allocation over 512 MB"; fi
  echo "fuzz: $target: ${seconds} s, $runs runs, $speed/s, corpus $corpus, slowest input ${slowest_ms:-?} ms: $verdict"
done

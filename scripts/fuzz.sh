#!/usr/bin/env bash
# Runs every file reader under libFuzzer for a time budget each, seeded with the test fixtures:
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]      (default 1800 s, every target)
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`). Each input may take
# at most 1 s and 512 MB of allocation (-timeout, -malloc_limit_mb); a crash, hang or
# allocation over the limit stops the target and leaves its input in fuzz/artifacts/TARGET/.
# Prints one line a target: runs, executions a second, corpus size, and the verdict.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-1800}"
shift || true
targets=("$@")
if [ "${#targets[@]}" -eq 0 ]; then
  targets=(bvh gltf fbx audio bone_map)
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
  esac
}

cargo +nightly fuzz build -O
for target in "${targets[@]}"; do
  seed "$target"
  log="fuzz/artifacts/$target.log"
  mkdir -p fuzz/artifacts
  status=0
  cargo +nightly fuzz run -O "$target" "fuzz/corpus/$target" -- \
    -max_total_time="$seconds" -timeout=1 -malloc_limit_mb=512 -rss_limit_mb=2048 \
    -max_len=1048576 -print_final_stats=1 >"$log" 2>&1 || status=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  corpus=$(find "fuzz/corpus/$target" -type f | wc -l)
  if [ "$status" -eq 0 ]; then verdict="no crash, no hang over 1 s, no allocation over 512 MB"
  else verdict="FAILED (see $log and fuzz/artifacts/$target/)"; fi
  echo "fuzz: $target: ${seconds} s, $runs runs, $speed/s, corpus $corpus: $verdict"
done

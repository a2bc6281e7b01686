#!/usr/bin/env bash
# A motion library on this machine, two ways, side by side: every clip of a folder (the README's
# figure used the project's shared clips) trained with one configuration (default: the default)
#   1. through a Slurm job array on a single-node Slurm (tests/cluster/slurm_node.sh), at most 2
#      tasks at once with one thread each (--array=0-N%2 --cpus-per-task=1);
#   2. one after another with two threads each (sinmdm-train --manifest M --index i --threads 2).
# Prints the wall time of both and each clip's training minutes (from `sinmdm library report`).
# The default configuration takes about an hour per leg on 2 cores: run it with nothing else on
# the machine (it refuses to start while another sinmdm-train runs).
# Usage: lab/scripts/bench_library.sh CLIPS_DIR [CONFIG.yaml] [WORK_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
[ $# -ge 1 ] || { echo "usage: $0 CLIPS_DIR [CONFIG.yaml] [WORK_DIR]" >&2; exit 2; }
[ -d "$1" ] || { echo "no folder of clips at $1" >&2; exit 2; }
clips=$(cd "$1" && pwd)
config=${2:-}
if [ $# -ge 3 ]; then work=$3; mkdir -p "$work"; else work=$(mktemp -d); fi
work=$(cd "$work" && pwd)
bin="$repo/target/release"
fail() {
  echo "FAIL: $*" >&2
  for log in "$work"/slurm/*.log; do [ -f "$log" ] && { echo "--- $log" >&2; tail -n 20 "$log" >&2; }; done
  exit 1
}
if pgrep -x sinmdm-train >/dev/null; then fail "another sinmdm-train is running; the figures would not compare"; fi
for tool in munged slurmctld slurmd sbatch squeue; do
  command -v "$tool" >/dev/null || fail "$tool is not installed (scripts/setup_tests.sh installs it)"
done
(cd "$repo" && cargo build --release -q -p sinmdm-train -p sinmdm-cli)
export ORT_DYLIB_PATH=${ORT_DYLIB_PATH:-$(ls "$repo"/.venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.1* | head -n 1)}
export SINMDM_BIN="$bin"

# One manifest per leg, the same clips and configuration, each its own output folder.
mapfile -t files < <(cd "$clips" && ls -1 ./*.bvh | sed 's|^\./||' | sort)
[ "${#files[@]}" -gt 0 ] || fail "no .bvh clips in $clips"
count=${#files[@]}
for leg in array serial; do
  mkdir -p "$work/$leg"
  {
    [ -n "$config" ] && echo "config: $(cd "$(dirname "$config")" && pwd)/$(basename "$config")"
    echo "samples: 4"
    echo "clips:"
    for f in "${files[@]}"; do echo "  - clip: $clips/$f"; done
  } > "$work/$leg/library.yaml"
done
echo "clips: $count from $clips; configuration: ${config:-the default}; work: $work"

# 1. The array, 2 at a time, one thread each.
# shellcheck source=tests/cluster/slurm_node.sh
. "$repo/tests/cluster/slurm_node.sh"
trap slurm_node_stop EXIT
slurm_node_start "$work"
start=$(date +%s.%N)
job=$(cd "$work/array" && sbatch --parsable --array="0-$((count - 1))%2" --cpus-per-task=1 \
  --time=04:00:00 --output="$work/slurm/task-%A_%a.out" \
  "$repo/scripts/cluster/slurm_array.sbatch" "$work/array/library.yaml")
job=${job%%;*}
while [ -n "$(squeue -h -j "$job" 2>/dev/null)" ]; do sleep 2; done
array_s=$(echo "$(date +%s.%N) - $start" | bc)
slurm_node_stop
trap - EXIT
echo "array: $array_s s"

# 2. One after another, two threads each.
start=$(date +%s.%N)
for i in $(seq 0 $((count - 1))); do
  "$bin/sinmdm-train" --manifest "$work/serial/library.yaml" --index "$i" --threads 2 \
    > "$work/serial/task-$i.out" 2>&1 || echo "serial task $i failed (see $work/serial/task-$i.out)"
done
serial_s=$(echo "$(date +%s.%N) - $start" | bc)
echo "serial: $serial_s s"

for leg in array serial; do
  "$bin/sinmdm" library report --manifest "$work/$leg/library.yaml" -o "$work/$leg/report" >/dev/null
done
python3 - "$work" "$array_s" "$serial_s" "$count" <<'PY'
import json, sys
work, array_s, serial_s, count = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
def rows(leg):
    return {r["name"]: r for r in json.load(open(f"{work}/{leg}/report/report.json"))}
a, s = rows("array"), rows("serial")
def minutes(r):
    t = r.get("training_seconds")
    return f"{t / 60:.1f}" if isinstance(t, (int, float)) else r.get("standing", "?")
print(f"| way | wall time | clips done |")
print(f"|---|---|---|")
done = lambda rs: sum(1 for r in rs.values() if r.get("standing") == "done")
print(f"| Slurm array, 2 at a time, 1 thread each | {array_s / 60:.1f} min | {done(a)} of {count} |")
print(f"| one after another, 2 threads each | {serial_s / 60:.1f} min | {done(s)} of {count} |")
print(f"array / one after another: {array_s / serial_s:.2f}")
print()
print("| clip | training min, array (1 thread) | training min, one after another (2 threads) |")
print("|---|---|---|")
for name in sorted(a):
    print(f"| {name} | {minutes(a[name])} | {minutes(s.get(name, {}))} |")
PY

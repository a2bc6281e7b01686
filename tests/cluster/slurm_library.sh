#!/usr/bin/env bash
# A motion library on a real single-node Slurm: munged, slurmctld and slurmd run in the
# foreground as children of this script, with every file in a temporary folder, and are stopped
# at the end. Checks, on the shipped clips with a short training:
#   1. an array of 4 tasks over 4 clips, at most 2 at once: all 4 models appear, with cards;
#   2. a task killed mid-run and submitted again resumes from its checkpoint (its loss log
#      goes on from the checkpoint's step, it does not restart);
#   3. a second submission of the whole array trains nothing;
#   4. changing one clip retrains exactly that one;
#   5. a clip that does not parse fails with its error in `sinmdm library status`, the others
#      unharmed; `sinmdm library report` writes the table and the contact sheet.
# Skips (exit 0, a line starting "SKIP") where the Slurm packages are missing.
# Usage: tests/cluster/slurm_library.sh [WORK_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
for tool in munged slurmctld slurmd sbatch squeue scancel; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool is not installed (scripts/setup_tests.sh installs slurmctld slurmd slurm-client munge)"
    exit 0
  fi
done
# munged wants every folder above its socket to be reachable by all, so a work folder under a
# private one (pytest's tmp_path) will not do: by default a fresh folder in /tmp, removed after a
# success.
own_work=0
if [ $# -ge 1 ]; then work=$1; else work=$(mktemp -d); own_work=1; fi
mkdir -p "$work"
work=$(cd "$work" && pwd)
bin="$repo/target/release"
# shellcheck source=tests/cluster/slurm_node.sh
. "$repo/tests/cluster/slurm_node.sh"
trap slurm_node_stop EXIT
fail() {
  echo "FAIL: $*" >&2
  for log in "$work"/slurm/*.log; do echo "--- $log" >&2; tail -n 20 "$log" >&2; done
  exit 1
}
slurm_node_start "$work"

# The library: four shipped clips, a short training (one of them long enough to be killed).
lib="$work/lib"
mkdir -p "$lib"
for clip in human_walk_cmu_131_01 human_hop_cmu_131_03 fox_survey_khronos human_dance_rokoko_jesse; do
  cp "$repo/tests/data/bvh/$clip.bvh" "$lib/"
done
sed 's/^  steps: 300/  steps: 40/; s/^  checkpoint_every: 100/  checkpoint_every: 20/' "$repo/configs/tiny.yaml" > "$lib/short.yaml"
sed 's/^  steps: 300/  steps: 600/; s/^  checkpoint_every: 100/  checkpoint_every: 20/' "$repo/configs/tiny.yaml" > "$lib/long.yaml"
grep -q 'steps: 40' "$lib/short.yaml" || fail "configs/tiny.yaml changed shape"
cat > "$lib/library.yaml" <<YAML
config: short.yaml
samples: 2
clips:
  - clip: human_walk_cmu_131_01.bvh
    name: walk
  - clip: human_hop_cmu_131_03.bvh
    name: hop
  - clip: fox_survey_khronos.bvh
    name: fox
  - clip: human_dance_rokoko_jesse.bvh
    name: dance
    config: long.yaml
YAML
manifest="$lib/library.yaml"
out="$lib/library"
cd "$work"
export SINMDM_BIN="$bin"
export ORT_DYLIB_PATH=${ORT_DYLIB_PATH:-$(ls "$repo"/.venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.1* | head -n 1)}

# Submits the library's array (sbatch arguments), waits for it, prints the job id.
submit() {
  local job
  job=$(sbatch --parsable --cpus-per-task=1 --output="$work/slurm/task-%A_%a.out" "$@" \
    "$repo/scripts/cluster/slurm_array.sbatch" "$manifest") || fail "sbatch refused: $*"
  echo "${job%%;*}"
}
wait_for() {
  local job=$1
  for _ in $(seq 1 600); do
    [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && return 0
    sleep 0.5
  done
  fail "job $job did not finish"
}
watch_concurrency() {
  # Samples the job while it is queued: the most tasks seen running at once, into a file.
  local job=$1 file=$2 seen=0 now
  sleep 0.5
  while [ -n "$(squeue -h -j "$job" 2>/dev/null)" ]; do
    now=$(squeue -h -j "$job" -t RUNNING 2>/dev/null | wc -l)
    [ "$now" -gt "$seen" ] && seen=$now
    echo "$seen" > "$file"
    sleep 0.2
  done
}

# 1. The array of 4, at most 2 at once; the long task (dance) is killed once it has a
#    checkpoint, while the others finish.
job=$(submit --array=0-3%2)
echo "submitted array $job"
watch_concurrency "$job" "$work/most_running" &
watcher=$!
for _ in $(seq 1 600); do
  [ -e "$out/dance/run/latest" ] && break
  sleep 0.5
done
[ -e "$out/dance/run/latest" ] || fail "the long task never saved a checkpoint"
scancel --signal=KILL "${job}_3"
wait_for "$job"
wait "$watcher" || true
most=$(cat "$work/most_running" 2>/dev/null || echo 0)
[ "$most" -ge 1 ] && [ "$most" -le 2 ] || fail "$most tasks ran at once; the limit was 2"
for name in walk hop fox; do
  [ -f "$out/$name/model.onnx" ] && [ -f "$out/$name/card.md" ] || fail "$name has no model or card"
done
[ -f "$out/dance/model.onnx" ] && fail "the killed task has a model"
killed_rows=$(($(wc -l < "$out/dance/run/loss.csv") - 1))
echo "1. three models with cards, at most $most tasks at once; the long task killed after $killed_rows logged steps"

# 2. The killed task again, with the same settings: it resumes from its checkpoint.
job=$(submit --array=3)
wait_for "$job"
grep -q "resumed and finished" "$work/slurm/task-${job}_3.out" || fail "the task did not resume: $(cat "$work/slurm/task-${job}_3.out")"
python3 - "$out/dance/run/loss.csv" <<'PY' || fail "the resumed loss log restarted"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))[1:]
steps = [int(r[0]) for r in rows]
assert steps == list(range(1, len(steps) + 1)), steps[:5]
assert len(steps) == 600, len(steps)
PY
echo "2. the killed task resumed from its checkpoint and its loss log went on"

# 3. The whole array again: nothing trains.
before=$(stat -c %Y "$out"/*/model.onnx | tr '\n' ' ')
job=$(submit --array=0-3%2)
wait_for "$job"
after=$(stat -c %Y "$out"/*/model.onnx | tr '\n' ' ')
[ "$before" = "$after" ] || fail "a second submission rewrote a model"
for i in 0 1 2 3; do
  grep -q "up to date" "$work/slurm/task-${job}_$i.out" || fail "task $i trained again"
done
echo "3. a second submission trained nothing"

# 4. One clip changed (the hop replaced by a cut of itself): exactly that one retrains.
sleep 1
head -n 400 "$repo/tests/data/bvh/human_hop_cmu_131_03.bvh" > "$lib/human_hop_cmu_131_03.bvh"
frames=$(grep -c '' "$lib/human_hop_cmu_131_03.bvh")
python3 - "$lib/human_hop_cmu_131_03.bvh" <<'PY'
import sys
path = sys.argv[1]
lines = open(path).read().splitlines()
start = next(i for i, l in enumerate(lines) if l.startswith("Frames:"))
motion = lines[start + 2:]
lines[start] = f"Frames: {len(motion)}"
open(path, "w").write("\n".join(lines) + "\n")
PY
job=$(submit --array=0-3%2)
wait_for "$job"
retrained=$(grep -l "trained " "$work/slurm/task-${job}"_*.out | wc -l)
grep -q "trained " "$work/slurm/task-${job}_1.out" || fail "the changed clip was not retrained"
[ "$retrained" = 1 ] || fail "$retrained tasks retrained, not 1"
echo "4. changing one clip retrained exactly that one ($frames lines)"

# 5. A clip that does not parse: its task fails with the error, the report covers the rest.
echo "HIERARCHY oops" > "$lib/broken.bvh"
printf '  - clip: broken.bvh\n' >> "$manifest"
job=$(submit --array=4)
wait_for "$job"
status=$("$bin/sinmdm" library status --manifest "$manifest")
echo "$status"
echo "$status" | grep -q "^broken .*failed: .*broken.bvh" || fail "status does not show the failure"
echo "$status" | grep -q "4 done" || fail "the other clips are not all done"
"$bin/sinmdm" library report --manifest "$manifest" -o "$work/report" >/dev/null
grep -q "| walk | done |" "$work/report/report.md" || fail "no table"
[ -s "$work/report/contact_sheet.png" ] || fail "no contact sheet"
echo "5. a failed clip is reported with its error; report.md and contact_sheet.png written"
echo "slurm library: all checks passed"
trap - EXIT
slurm_node_stop
if [ "$own_work" = 1 ]; then rm -rf "$work"; fi

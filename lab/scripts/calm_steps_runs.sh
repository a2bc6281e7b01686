#!/usr/bin/env bash
# Trains the project's calm clips (own intra diversity under 0.7) with steps that fall with the
# clip's calm, round(300 * min(1, intra / R) ** P), at least 50 (warm-up a third), the default
# otherwise, and scores each (lab/scripts/variant_runs.sh): the leave-one-out's p settings.
#
# Usage: [R=0.65] lab/scripts/calm_steps_runs.sh SHARED_BVH_DIR P...
#   runs go to out/variants/CLIP.pP (or CLIP.pPrRR for R 0.RR), with the config beside them.
# Pause any other training or benchmark while this runs: the times are wall-clock.
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=${1:?usage: calm_steps_runs.sh SHARED_BVH_DIR P...}
shift
reference=${R:-0.7}
base_config=$(mktemp --suffix=.yaml)
trap 'rm -f "$base_config"' EXIT
# The default with the rule off (its section is the file's last): the steps below are the only
# change.
sed '/^from_clip:/,$d' configs/default.yaml >"$base_config"
declare -A intra=([human_kick_bandai]=0.6437676 [human_dance_rokoko]=0.6156872
  [human_zombie_walk_fair]=0.5328391 [human_walk_happy_bandai]=0.5097781
  [human_walk_sad_bandai]=0.3378443 [fox_survey_khronos]=0.1635484)
for p in "$@"; do
  name=p$p
  [ "$reference" != 0.7 ] && name=p${p}r${reference#0.}
  for clip in "${!intra[@]}"; do
    steps=$(python3 -c "print(max(50, round(300 * min(1, ${intra[$clip]} / $reference) ** $p)))")
    warm=$(python3 -c "print(round($steps / 3))")
    config=out/variants/$name.$clip.yaml
    mkdir -p out/variants
    python3 - "$base_config" "$config" "$steps" "$warm" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
head, training = text.split("\ntraining:\n", 1)
training = re.sub(r"(?m)^  steps: \d+", f"  steps: {sys.argv[3]}", training, count=1)
training = re.sub(r"(?m)^  warmup_steps: \d+", f"  warmup_steps: {sys.argv[4]}", training, count=1)
text = head + "\ntraining:\n" + training
open(sys.argv[2], "w").write(text)
PY
    echo "$clip $name: $steps steps"
    CLIPS=$clip lab/scripts/variant_runs.sh "$shared" "$name" "$config" | grep -v "^wrote"
  done
done

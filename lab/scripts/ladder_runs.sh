#!/usr/bin/env bash
# Trains clips of the project with the default (the rule that reads the clip, step ladder
# included) and judges each with `sinmdm eval` (20 samples of twice the clip, default sampling,
# seed 0: not the ladder's own seed 1), as lab/scripts/variant_runs.sh does. The rungs' own
# scores are in each run's step_ladder/steps-N/check.json and in its .log.
#
# Usage: [CLIPS="..."] lab/scripts/ladder_runs.sh SHARED_BVH_DIR   (runs: out/variants/CLIP.ladder)
# Pause any other training or benchmark while this runs: the times are wall-clock.
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=${1:?usage: ladder_runs.sh SHARED_BVH_DIR}
CLIPS=${CLIPS:-"human_kick_bandai human_dance_rokoko human_zombie_walk_fair human_walk_happy_bandai human_walk_sad_bandai fox_survey_khronos"} \
  lab/scripts/variant_runs.sh "$shared" ladder -

# The project's clips by the names the lab's tables use, each its file in the shared BVH folder
# (sourced by the lab's drivers: `source lab/scripts/project_clips.sh`).
# shellcheck disable=SC2034  # used by the scripts that source it
declare -A project_clip_files=(
  [human_kick_bandai]=human_kick_bandai_kick_normal_001.bvh
  [human_walk_happy_bandai]=human_walk_happy_bandai_001.bvh
  [human_walk_sad_bandai]=human_walk_sad_bandai_001.bvh
  [dog_run_mann]=dog_run_mann_d1_010_kan01_004.bvh
  [human_zombie_walk_fair]=human_zombie_walk_fair.bvh
  [fox_survey_khronos]=fox_survey_khronos.bvh
  [human_dance_rokoko]=human_dance_rokoko_jesse.bvh
  [human_walk_cmu]=human_walk_cmu_131_01.bvh
  [human_hop_cmu]=human_hop_cmu_131_03.bvh
  [dog_walk_mann]=dog_walk_mann_d1_047z_kan01_004.bvh
)

#!/usr/bin/env bash
# How long a new user waits for the main job: `scripts/demo.sh` in a fresh clone with an empty
# target folder and no .venv (crates, wheels and node packages already in their caches, so the
# network is not what is measured), for this commit and for BEFORE, one after the other in one
# run. Prints, for each, the seconds to the first GIF (out/walk_new.gif) and to the end.
# Usage: lab/scripts/bench_first_motion.sh [BEFORE_COMMIT]   (default: e65028b, the last commit
# whose demo ran the tests' set-up)
# Pause any training while this runs: this machine has two cores.
set -euo pipefail
cd "$(dirname "$0")/../.."
before=${1:-e65028b}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
head=$(git rev-parse --short HEAD)
run() { # NAME COMMIT
  local clone="$work/$1"
  git clone --quiet --no-hardlinks . "$clone"
  git -C "$clone" checkout --quiet "$2"
  local start first="" status=0
  start=$(date +%s.%N)
  (cd "$clone" && CARGO_TARGET_DIR="$clone/target" scripts/demo.sh out >"$work/$1.log" 2>&1) &
  local demo=$!
  while kill -0 "$demo" 2>/dev/null; do
    if [ -z "$first" ] && [ -s "$clone/out/walk_new.gif" ]; then
      first=$(echo "$(date +%s.%N) - $start" | bc)
    fi
    sleep 1
  done
  wait "$demo" || status=$?
  local end
  end=$(echo "$(date +%s.%N) - $start" | bc)
  printf '%-8s %-9s first GIF %7.1f s   done %7.1f s   exit %d\n' "$1" "$2" "${first:-nan}" "$end" "$status"
  rm -rf "$clone"
}
echo "scripts/demo.sh from a fresh clone, $(nproc) cores, $(date -u +%F)"
run now "$head"
run before "$before"

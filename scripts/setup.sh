#!/usr/bin/env bash
# Sets up what the main job needs (scripts/demo.sh: the `sinmdm` command line on the shipped
# models) and nothing more, without root:
#  - a release build of the `sinmdm` command line (no burn, no trainer);
#  - an onnxruntime shared library for it to load: any onnxruntime 1.17 or later it already
#    finds (`sinmdm doctor` says which and where), else the pinned wheel in a project-local
#    .venv (needs Python 3 with venv; scripts/requirements-runtime.txt).
# --train builds the whole workspace instead, the trainer and exporter included (sinmdm-train,
# sinmdm-export: burn, about ten minutes on 2 cores the first time); so does any later run once
# the trainer is built: the command line alone resolves its dependencies' features apart from
# the workspace, and building the two in turn would rebuild most crates each time. The tests'
# own set-up is scripts/setup_tests.sh.
# Safe to run again: it builds incrementally and installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

train=0
for arg in "$@"; do
  case "$arg" in
    --train) train=1 ;;
    *) echo "setup: unknown argument '$arg' (usage: scripts/setup.sh [--train])" >&2; exit 2 ;;
  esac
done
if ! command -v cargo >/dev/null; then
  echo "setup: cargo not found; install Rust from https://rustup.rs" >&2
  exit 1
fi

packages=(-p sinmdm-cli)
what="the sinmdm command line"
release=${CARGO_TARGET_DIR:-target}/release
if [ "$train" = 1 ] || [ -x "$release/sinmdm-train" ]; then
  packages=(--workspace)
  what="the workspace (sinmdm, sinmdm-train, sinmdm-export)"
fi
echo "setup: building $what (release)"
cargo build --release --quiet "${packages[@]}"
sinmdm=$release/sinmdm

if ! "$sinmdm" doctor >/dev/null 2>&1; then
  python=${PYTHON:-python3}
  echo "setup: no onnxruntime found; installing the pinned wheel into .venv (its shared library is what sinmdm loads)"
  if ! command -v "$python" >/dev/null; then
    echo "setup: $python not found: install Python 3.10+ (or set PYTHON=/path/to/python3), or put" \
      "onnxruntime 1.17+ next to $sinmdm or on the system's library path" >&2
    exit 1
  fi
  if [ ! -x .venv/bin/python ] && ! "$python" -m venv .venv; then
    echo "setup: '$python -m venv' failed (on Debian or Ubuntu: the python3-venv package); or put" \
      "onnxruntime 1.17+ next to $sinmdm or on the system's library path" >&2
    exit 1
  fi
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r scripts/requirements-runtime.txt
  if ! "$sinmdm" doctor >/dev/null 2>&1; then
    "$sinmdm" doctor >&2 || true
    exit 1
  fi
fi
echo "setup: $("$sinmdm" doctor | sed -n 2p)"
echo "setup: done"

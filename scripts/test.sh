#!/usr/bin/env bash
# Runs every test: the Rust workspace (release build: the training crate is unusably slow in
# debug) and the Python tests that check our output with independent readers. Each part prints
# how long it took.
set -euo pipefail
cd "$(dirname "$0")/.."
part() { # NAME COMMAND...
  local name=$1 start=$SECONDS
  shift
  "$@"
  echo "test: $name took $((SECONDS - start)) s"
}
part setup-tests scripts/setup_tests.sh
part setup scripts/setup.sh
part workspace cargo test --release --workspace
# burn's ONNX importer on an exported model: a crate with its own lockfile (burn-onnx needs
# protobuf 3.7, the export crate pins 3.4.0), built into its own target folder.
part burn-import env CARGO_TARGET_DIR=target/burn-import-check \
  cargo test --release --manifest-path tests/burn-import-check/Cargo.toml
# MP3/OGG/FLAC input is a feature of the beat tracker's crate (symphonia), tested in its own
# target folder so the workspace's default-feature build is not rebuilt back and forth.
part compressed env CARGO_TARGET_DIR=target/compressed cargo test --release -p sinmdm-beats --features compressed
# The Bevy plugin: its own workspace and lockfile (Bevy's crates stay out of the main build),
# tested with its AnimationClip feature in its own target folder.
part bevy env CARGO_TARGET_DIR=target/bevy CARGO_INCREMENTAL=0 cargo test --locked --manifest-path bindings/bevy/Cargo.toml --features animation-clip
part python .venv/bin/python -m pytest -q --durations=15 tests/python

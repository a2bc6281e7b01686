#!/usr/bin/env bash
# Runs every test: the Rust workspace (release build: the training crate is unusably slow in
# debug) and the Python tests that check our output with independent readers.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/setup_tests.sh
cargo test --release --workspace
# burn's ONNX importer on an exported model: a crate with its own lockfile (burn-onnx needs
# protobuf 3.7, the export crate pins 3.4.0), built into its own target folder.
CARGO_TARGET_DIR=target/burn-import-check \
  cargo test --release --manifest-path tests/burn-import-check/Cargo.toml
# MP3/OGG/FLAC input is a feature of the beat tracker's crate (symphonia), tested in its own
# target folder so the workspace's default-feature build is not rebuilt back and forth.
CARGO_TARGET_DIR=target/compressed cargo test --release -p sinmdm-beats --features compressed
# The Bevy plugin: its own workspace and lockfile (Bevy's crates stay out of the main build),
# tested with its AnimationClip feature in its own target folder.
CARGO_TARGET_DIR=target/bevy cargo test --locked --manifest-path bindings/bevy/Cargo.toml --features animation-clip
.venv/bin/python -m pytest -q tests/python

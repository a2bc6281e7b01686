#!/usr/bin/env bash
# Runs every test: the Rust workspace (release build: the training crate is unusably slow in
# debug) and the Python tests that check our output with independent readers.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo test --release --workspace
# burn's ONNX importer on an exported model: a crate with its own lockfile (burn-onnx needs
# protobuf 3.7, the export crate pins 3.4.0), built into its own target folder.
CARGO_TARGET_DIR=target/burn-import-check \
  cargo test --release --manifest-path tests/burn-import-check/Cargo.toml
.venv/bin/python -m pytest -q tests/python

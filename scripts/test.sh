#!/usr/bin/env bash
# Runs every test: the Rust workspace (release build: the training crate is unusably slow in
# debug) and the Python tests that check our output with independent readers.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo test --release --workspace
.venv/bin/python -m pytest -q tests/python

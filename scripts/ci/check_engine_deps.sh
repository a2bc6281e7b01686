#!/usr/bin/env bash
# The engine library's normal dependencies (default features) must hold nothing an engine does
# not need: no command-line, progress-bar, picture or file-format (glTF, FBX) crates. Fails naming any that crept in.
set -euo pipefail
cd "$(dirname "$0")/../.."
tree=$(cargo tree -p sinmdm -e normal --prefix none --format '{p}' | awk '{print $1}' | sort -u)
bad=$(echo "$tree" | grep -xE 'clap|clap_builder|anyhow|indicatif|gif|png|burn|burn-.*|gltf|gltf-.*|ufbx|sinmdm-formats' || true)
if [ -n "$bad" ]; then
  echo "check_engine_deps: the sinmdm crate depends on: $(echo $bad)" >&2
  exit 1
fi
echo "check_engine_deps: sinmdm depends on $(echo "$tree" | wc -l) crates, none of clap, anyhow, indicatif, gif, png, burn, gltf, ufbx, sinmdm-formats"

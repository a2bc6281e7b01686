#!/usr/bin/env bash
# Sets up a fresh checkout: a project-local Python virtual environment (.venv) with the pinned
# onnxruntime wheel, whose shared library the Rust runtime loads, then a release build.
# Safe to run again: it only reinstalls when scripts/requirements.txt changed.
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
if ! command -v "$python" >/dev/null; then
  echo "setup: $python not found; install Python 3.10+ or set PYTHON=/path/to/python3" >&2
  exit 1
fi
if ! command -v cargo >/dev/null; then
  echo "setup: cargo not found; install Rust from https://rustup.rs" >&2
  exit 1
fi

# The tools the C ABI's tests run: a C compiler, valgrind (memcheck) and Mono (the C# binding).
missing=()
command -v cc >/dev/null || missing+=(gcc)
command -v valgrind >/dev/null || missing+=(valgrind)
command -v mcs >/dev/null || missing+=(mono-mcs)
command -v mono >/dev/null || missing+=(mono-runtime)
# A real single-node Slurm for the library's cluster test (the daemons run as test processes).
cluster=()
command -v slurmctld >/dev/null || cluster+=(slurmctld)
command -v slurmd >/dev/null || cluster+=(slurmd)
command -v sbatch >/dev/null || cluster+=(slurm-client)
command -v munged >/dev/null || cluster+=(munge)
if [ ${#missing[@]} -gt 0 ] || [ ${#cluster[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "setup: installing ${missing[*]} ${cluster[*]}"
    apt-get update -qq
    if [ ${#missing[@]} -gt 0 ]; then
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    fi
    if [ ${#cluster[@]} -gt 0 ]; then
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${cluster[@]}" >/dev/null
    fi
  else
    echo "setup: the C ABI and cluster tests need ${missing[*]} ${cluster[*]}; install them as root with apt-get" >&2
  fi
fi

if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$python" -m venv .venv
fi
stamp=.venv/.sinmdm-requirements
if ! cmp -s scripts/requirements.txt "$stamp"; then
  echo "setup: installing Python packages (onnxruntime, onnx, numpy, bvhio, pytest, pyyaml, librosa)"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r scripts/requirements.txt
  cp scripts/requirements.txt "$stamp"
fi
lib=$(ls .venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.* 2>/dev/null | head -n 1 || true)
if [ -z "$lib" ]; then
  echo "setup: the onnxruntime wheel has no shared library in .venv; remove .venv and run again" >&2
  exit 1
fi
echo "setup: onnxruntime library at $lib"
# The Python reference (python/), installed in editable mode so its sources are what runs.
if ! .venv/bin/python -c "import sinmdm_reference" 2>/dev/null; then
  echo "setup: installing the Python reference (python/) in editable mode"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check --no-deps -e python
fi

# The independent glTF readers the tests run under node (the Khronos validator, three.js),
# pinned by tests/node/package-lock.json.
if command -v npm >/dev/null; then
  node_stamp=tests/node/node_modules/.sinmdm-lock
  if ! cmp -s tests/node/package-lock.json "$node_stamp"; then
    echo "setup: installing the node packages of tests/node (gltf-validator, three)"
    npm ci --prefix tests/node --no-audit --no-fund --loglevel=error
    cp tests/node/package-lock.json "$node_stamp"
  fi
else
  echo "setup: node and npm are needed for the glTF tests (as root: apt-get install nodejs npm)" >&2
fi

echo "setup: building (release)"
cargo build --release --workspace --quiet
echo "setup: done"

#!/usr/bin/env bash
# Sets up what the tests need beyond the main job's set-up (scripts/setup.sh), and says what it
# installs and why:
#  - with apt, as root only: a C compiler, valgrind and Mono (the C ABI's and C# binding's
#    checks), and a single-node Slurm with munge (the library's cluster test);
#  - a project-local .venv with the pinned onnxruntime the tests compare bits with, the Python
#    reference (python/, editable) and the independent readers (scripts/requirements.txt);
#  - the node packages of tests/node (the Khronos glTF validator, three.js);
#  - PyPI's bpy (Blender 4.5 as a Python module) in its own .venv-blender, as Blender's own
#    Python: the add-on's test (blender/) runs it headless, with nothing else installed there;
#  - a release build of the whole workspace, the trainer included.
# Safe to run again: it installs only what is missing or changed.
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
if ! command -v "$python" >/dev/null; then
  echo "setup: $python not found; install Python 3.10+ or set PYTHON=/path/to/python3" >&2
  exit 1
fi

missing=()
command -v cc >/dev/null || missing+=(gcc)
command -v valgrind >/dev/null || missing+=(valgrind)
command -v mcs >/dev/null || missing+=(mono-mcs)
command -v mono >/dev/null || missing+=(mono-runtime)
cluster=()
command -v slurmctld >/dev/null || cluster+=(slurmctld)
command -v slurmd >/dev/null || cluster+=(slurmd)
command -v sbatch >/dev/null || cluster+=(slurm-client)
command -v munged >/dev/null || cluster+=(munge)
if [ ${#missing[@]} -gt 0 ] || [ ${#cluster[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "setup: installing ${missing[*]} ${cluster[*]} (the C ABI, C# and cluster tests run them)"
    apt-get update -qq
    if [ ${#missing[@]} -gt 0 ]; then
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    fi
    if [ ${#cluster[@]} -gt 0 ]; then
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${cluster[@]}" >/dev/null
    fi
  else
    echo "setup: the C ABI, C# and cluster tests need ${missing[*]} ${cluster[*]}; install them as root with apt-get" >&2
  fi
fi

if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$python" -m venv .venv
fi
stamp=.venv/.sinmdm-requirements
if ! cat scripts/requirements-runtime.txt scripts/requirements.txt | cmp -s - "$stamp"; then
  echo "setup: installing the tests' Python packages (onnxruntime, onnx, numpy, bvhio, pytest, pyyaml, librosa)"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r scripts/requirements.txt
  cat scripts/requirements-runtime.txt scripts/requirements.txt > "$stamp"
fi
lib=$(ls .venv/lib/python3*/site-packages/onnxruntime/capi/libonnxruntime.so.* 2>/dev/null | head -n 1 || true)
if [ -z "$lib" ]; then
  echo "setup: the onnxruntime wheel has no shared library in .venv; remove .venv and run again" >&2
  exit 1
fi
echo "setup: the tests' onnxruntime library at $lib"
if ! .venv/bin/python -c "import sinmdm_reference" 2>/dev/null; then
  echo "setup: installing the Python reference (python/) in editable mode"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check --no-deps -e python
fi

# bpy 4.5 is built for CPython 3.11 only; the add-on's test runs in this venv, apart from .venv
# (whose numpy and onnxruntime pins are the runtime's, not Blender's).
bpy_pin="bpy==4.5.15"
if [ "$(.venv-blender/bin/python -c 'import importlib.metadata as m; print(m.version("bpy"))' 2>/dev/null)" != "${bpy_pin#bpy==}" ]; then
  blender_python=""
  for candidate in "$python" python3.11; do
    if command -v "$candidate" >/dev/null && [ "$("$candidate" -c 'import sys; print(sys.version_info[:2] == (3, 11))')" = True ]; then
      blender_python=$candidate
      break
    fi
  done
  if [ -z "$blender_python" ]; then
    echo "setup: the Blender add-on's test needs Python 3.11 (PyPI's bpy 4.5 is built for it); set PYTHON to one" >&2
    exit 1
  fi
  echo "setup: installing $bpy_pin into .venv-blender (the Blender add-on's test runs Blender headless)"
  rm -rf .venv-blender
  "$blender_python" -m venv .venv-blender
  .venv-blender/bin/python -m pip install --quiet --disable-pip-version-check "$bpy_pin"
fi

if command -v npm >/dev/null; then
  node_stamp=tests/node/node_modules/.sinmdm-lock
  if ! cmp -s tests/node/package-lock.json "$node_stamp"; then
    echo "setup: installing the node packages of tests/node (gltf-validator, three: the glTF tests read with them)"
    npm ci --prefix tests/node --no-audit --no-fund --loglevel=error
    cp tests/node/package-lock.json "$node_stamp"
  fi
else
  echo "setup: node and npm are needed for the glTF tests (as root: apt-get install nodejs npm)" >&2
fi

echo "setup: building the whole workspace (release)"
cargo build --release --workspace --quiet
echo "setup: the tests' set-up is done"

"""FBX files read by a reader that is not ours: three.js's FBXLoader (under node, with an
AnimationMixer) puts every bone where our reader does (its frames written out as BVH, positions
by bvhio), after three.js's centimetres and its name sanitising. The files: Blender's exports of
the walk and the fox (binary, armature only and skinned) and the Mixamo-style ASCII walk
(namespace, centimetres, pre- and post-rotations, '_End' bones)."""

import gzip
import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import ROOT, SINMDM, bvhio_joint_positions

NODE_DIR = ROOT / "tests" / "node"
FBX = ROOT / "tests" / "data" / "fbx"
# three.js keeps the files' centimetres; our reader gives metres.
THREE_UNITS_PER_METRE = 100.0


@pytest.fixture(scope="module", autouse=True)
def node_packages():
    if shutil.which("node") is None or not (NODE_DIR / "node_modules" / "three").is_dir():
        pytest.fail("node and tests/node/node_modules are needed: run scripts/setup_tests.sh")


def fixture(name, tmp_path):
    """The fixture's path, unpacked into `tmp_path` when it is stored compressed."""
    plain = FBX / name
    if plain.exists():
        return plain
    out = tmp_path / name
    out.write_bytes(gzip.decompress((FBX / (name + ".gz")).read_bytes()))
    return out


def sinmdm(*args):
    done = subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def three_key(name):
    """A bone name as three.js gives it, without Mixamo's namespace (which three.js runs into
    the name when it drops the ':')."""
    return re.sub(r"^mixamorig1?", "", re.sub(r"[\[\]\.:/]", "", re.sub(r"\s", "_", name)))


@pytest.mark.parametrize("name", [
    "human_walk_cmu_131_01_armature.fbx",
    "human_walk_cmu_131_01_skinned.fbx",
    "fox_survey_khronos_armature.fbx",
    "fox_survey_khronos_skinned.fbx",
    "human_walk_cmu_131_01_mixamo_style.fbx",
])
def test_three_puts_every_bone_where_our_reader_does(tmp_path, name):
    fbx = fixture(name, tmp_path)
    bvh = tmp_path / "read.bvh"
    sinmdm("convert", fbx, "-o", bvh)
    ours, names = bvhio_joint_positions(bvh)
    fps = 1.0 / float(re.search(r"Frame Time:\s*([0-9.eE+-]+)", bvh.read_text()).group(1))
    count = len(ours)

    probe = json.loads(subprocess.run(["node", str(NODE_DIR / "three_fbx_positions.mjs"), str(fbx), "0"],
                                      capture_output=True, text=True, check=True).stdout)
    assert len(probe["animations"]) == 1
    first = probe["animations"][0]["firstKey"]
    last = probe["animations"][0]["duration"]
    frames = [0, 1, count // 3, count // 2, count - 1]
    # three.js wraps to the start at the clip's end: the last frame is asked just before it.
    times = [min(first + f / fps, last - 1e-6) for f in frames]
    three = json.loads(subprocess.run(["node", str(NODE_DIR / "three_fbx_positions.mjs"), str(fbx),
                                       ",".join(map(str, times))],
                                      capture_output=True, text=True, check=True).stdout)

    index = {three_key(n): i for i, n in enumerate(names)}
    end_bones = [b for b in three["bones"] if re.search(r"_[Ee]nd$", b)]
    height = float(np.ptp(ours[..., 1], axis=1).mean())
    worst, matched = 0.0, 0
    for bone, bone_name in enumerate(three["bones"]):
        key = three_key(bone_name)
        if key not in index:
            assert bone_name in end_bones, f"three.js bone {bone_name} is not among our joints"
            continue
        matched += 1
        for k, frame in enumerate(frames):
            got = np.asarray(three["positions"][0][k][bone]) / THREE_UNITS_PER_METRE
            worst = max(worst, float(np.linalg.norm(got - ours[frame, index[key]])))
    # Every joint of ours was matched (the leaf '_end' bones are our End Sites).
    assert matched == len(names), (matched, len(names))
    assert len(end_bones) >= 2
    assert worst <= 1e-5 * height, f"worst {worst / height:.2e} of the height"

"""The glTF files sinmdm writes, read by readers that are not ours: the Khronos glTF validator
reports no error and no warning, and three.js (GLTFLoader + AnimationMixer under node) puts every
bone where bvhio's forward kinematics of the same motion as BVH puts the joint."""

import json
import pathlib
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import ROOT, SINMDM, bvhio_joint_positions

NODE_DIR = ROOT / "tests" / "node"
WALK = ROOT / "tests" / "data" / "bvh" / "human_walk_cmu_131_01.bvh"
FOX = ROOT / "tests" / "data" / "bvh" / "fox_survey_khronos.bvh"
ZOMBIE = ROOT.parent / "shared" / "data" / "bvh" / "human_zombie_walk_fair.bvh"
MODEL = ROOT / "onnx-models" / "human_walk_cmu.onnx"

# The file frame to glTF's (+Y up) for a +Z-up file: (x, y, z) -> (x, z, -y).
Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@pytest.fixture(scope="module", autouse=True)
def node_packages():
    if shutil.which("node") is None or not (NODE_DIR / "node_modules" / "three").is_dir():
        pytest.fail("node and tests/node/node_modules are needed: run scripts/setup_tests.sh")


def run(*args):
    done = subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def node(script, *args):
    done = subprocess.run(["node", str(NODE_DIR / script), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def three_name(name):
    """three.js's PropertyBinding.sanitizeNodeName: whitespace to '_', '[].:/' removed."""
    return re.sub(r"[\[\]\.:/]", "", re.sub(r"\s", "_", name))


def frame_times(count, fps, picks):
    """Seconds of frames `picks` (negative from the end); the last frame just before the clip's
    end, where three.js would wrap to frame 0."""
    frames = [p % count for p in picks]
    return frames, [min(f / fps, (count - 1) / fps - 1e-6) for f in frames]


def bvh_fps(path):
    """The file's frame rate, snapped to a whole rate when its Frame Time is one rounded
    (0.0083333 s is 120 fps), as the glTF writer's key times are."""
    text = pathlib.Path(path).read_text()
    fps = 1.0 / float(re.search(r"Frame Time:\s*([0-9.eE+-]+)", text).group(1))
    return float(round(fps)) if abs(fps - round(fps)) < 1e-3 * fps else fps


def compare(three, animation, bvh_positions, bvh_names, frames, turn, scale, height, missing=0):
    """Largest distance, relative to the height, between three.js's bones and bvhio's joints;
    up to `missing` bones may have no joint (static leaf bones our reader makes End Sites)."""
    index = {three_name(n): i for i, n in enumerate(bvh_names)}
    worst = 0.0
    matched = 0
    for bone, name in enumerate(three["bones"]):
        if name not in index and missing > 0:
            continue
        i = index[name]
        matched += 1
        for k, frame in enumerate(frames):
            expected = scale * (turn @ bvh_positions[frame, i])
            got = np.asarray(three["positions"][animation][k][bone])
            worst = max(worst, float(np.linalg.norm(expected - got)))
    assert matched >= len(three["bones"]) - missing, (matched, len(three["bones"]))
    return worst / (height * scale)


def test_the_validator_finds_no_error_or_warning(tmp_path):
    walk, fox, crowd = tmp_path / "walk.glb", tmp_path / "fox.gltf", tmp_path / "crowd.glb"
    fox_proxy, crowd_proxy = tmp_path / "fox_proxy.glb", tmp_path / "crowd_proxy.glb"
    run("convert", WALK, "-o", walk)
    run("convert", FOX, "-o", fox)
    run("convert", FOX, "-o", fox_proxy, "--proxy-mesh")
    run("generate", "-m", MODEL, "-o", crowd, "--count", 3, "--seconds", 3, "--quiet")
    run("generate", "-m", MODEL, "-o", crowd_proxy, "--count", 2, "--seconds", 2, "--proxy-mesh", "--quiet")
    report = node("validate.mjs", walk, fox, crowd, fox_proxy, crowd_proxy)
    for file, result in report.items():
        assert result["errors"] == 0 and result["warnings"] == 0, (file, result["messages"])
        # Only the skin unused by any mesh is reported, as information; with the proxy mesh
        # the skin is used and nothing at all is reported.
        allowed = set() if "proxy" in file else {"UNUSED_OBJECT"}
        assert set(result["infoCodes"]) <= allowed, (file, result["infoCodes"])
    assert report[str(crowd)]["animations"] == 3
    assert report[str(crowd_proxy)]["animations"] == 2


@pytest.mark.parametrize("clip,turn,scale", [(WALK, np.eye(3), 0.05), (ZOMBIE, Z_UP_TO_Y_UP, 0.01)],
                         ids=["walk, Y-up", "zombie, Z-up"])
def test_three_puts_every_bone_where_bvhio_puts_the_joint(tmp_path, clip, turn, scale):
    if not clip.exists():
        pytest.skip(f"{clip} is not beside the checkout")
    glb = tmp_path / "clip.glb"
    run("convert", clip, "-o", glb, "--unit-scale", scale)
    positions, names = bvhio_joint_positions(clip)
    height = float(np.ptp((positions @ turn.T)[..., 1], axis=1).mean())
    frames, times = frame_times(len(positions), bvh_fps(clip), [0, 1, 37, len(positions) // 2, -2, -1])
    three = node("three_positions.mjs", glb, ",".join(map(str, times)))
    assert len(three["animations"]) == 1
    assert len(three["bones"]) == len(re.findall(r"\b(ROOT|JOINT)\b", clip.read_text()))
    worst = compare(three, 0, positions, names, frames, turn, scale, height)
    assert worst <= 1e-5, f"worst {worst:.2e} of the height"


def test_a_generated_crowd_as_glb_matches_the_same_crowd_as_bvh(tmp_path):
    """The same model, seed and arguments written as one GLB and as three BVH files: three.js
    plays animation i where bvhio puts sample i."""
    glb, bvh = tmp_path / "crowd.glb", tmp_path / "crowd.bvh"
    args = ["-m", MODEL, "--count", 3, "--seed", 4, "--seconds", 4, "--quiet"]
    run("generate", *args, "-o", glb, "--unit-scale", 0.05)
    run("generate", *args, "-o", bvh)
    samples = [bvhio_joint_positions(tmp_path / f"crowd_{i:03}.bvh") for i in range(3)]
    count = len(samples[0][0])
    frames, times = frame_times(count, 30.0, [0, 5, count // 3, -1])
    three = node("three_positions.mjs", glb, ",".join(map(str, times)))
    assert [a["name"] for a in three["animations"]] == ["sample_000", "sample_001", "sample_002"]
    for i, (positions, names) in enumerate(samples):
        height = float(np.ptp(positions[..., 1], axis=1).mean())
        worst = compare(three, i, positions, names, frames, np.eye(3), 0.05, height)
        assert worst <= 1e-5, f"sample {i}: worst {worst:.2e} of the height"


FIXTURES = ROOT / "tests" / "data" / "gltf"


@pytest.mark.parametrize("name", ["human_walk_cmu_131_01", "fox_survey_khronos"])
@pytest.mark.parametrize("variant", ["step", "cubic", "armature"])
def test_our_reader_plays_blender_files_as_three_does(tmp_path, name, variant):
    """Blender's STEP, CUBICSPLINE and LINEAR files: our reader's frames (written out as BVH,
    positions by bvhio) against three.js's interpolants. A STEP sampler jumps at its keys, so
    three.js is asked half a frame later, where STEP holds the key's value."""
    glb = FIXTURES / f"{name}_{variant}.glb"
    bvh = tmp_path / "read.bvh"
    run("convert", glb, "-o", bvh)
    positions, names = bvhio_joint_positions(bvh)
    fps = bvh_fps(bvh)
    # The animation's first key time (the JSON chunk's accessor bounds).
    data = glb.read_bytes()
    gltf = json.loads(data[20:20 + int.from_bytes(data[12:16], "little")])
    first = min(gltf["accessors"][s["input"]]["min"][0] for s in gltf["animations"][0]["samplers"])
    count = len(positions)
    frames = [0, 1, count // 3, count // 2, count - 2]
    offset = 0.5 / fps if variant == "step" else 0.0
    times = [first + f / fps + offset for f in frames]
    three = node("three_positions.mjs", glb, ",".join(map(str, times)))
    height = float(np.ptp(positions[..., 1], axis=1).mean())
    # Blender's files carry a still bone at every End Site, which our reader makes End Sites.
    end_bones = sum(bool(re.search(r"_end$", b)) for b in three["bones"])
    assert end_bones >= 2
    worst = compare(three, 0, positions, names, frames, np.eye(3), 1.0, height, missing=end_bones)
    assert worst <= 1e-5, f"worst {worst:.2e} of the height"


def test_a_crowd_spliced_into_the_character_keeps_it_and_plays_as_the_bvh_crowd(tmp_path):
    """`generate --mesh-from` on Blender's skinned walk: the character's JSON is unchanged but for
    the appended arrays and the buffer length, its binary data is kept, the validator finds
    nothing the character did not already have, and three.js plays each new animation where
    bvhio puts the same sample written as BVH."""
    character = FIXTURES / "human_walk_cmu_131_01_skinned.glb"
    glb, bvh = tmp_path / "crowd.glb", tmp_path / "crowd.bvh"
    args = ["-m", MODEL, "--count", 3, "--seed", 5, "--seconds", 3, "--quiet"]
    run("generate", *args, "-o", glb, "--mesh-from", character)
    run("generate", *args, "-o", bvh)

    def chunks(path):
        data = path.read_bytes()
        length = int.from_bytes(data[12:16], "little")
        return json.loads(data[20:20 + length]), data[20 + length + 8:]

    (before, bin_before), (after, bin_after) = chunks(character), chunks(glb)
    for key in ("accessors", "bufferViews", "animations"):
        assert len(after[key]) > len(before[key])
        after[key] = after[key][:len(before[key])]
    assert len(json.loads(json.dumps(chunks(glb)[0]["animations"]))) == 1 + 3
    after["buffers"][0]["byteLength"] = before["buffers"][0]["byteLength"]
    assert after == before
    assert bin_after[:before["buffers"][0]["byteLength"]] == bin_before[:before["buffers"][0]["byteLength"]]

    report = node("validate.mjs", character, glb)
    ours, theirs = report[str(glb)], report[str(character)]
    assert ours["errors"] == 0
    assert sorted(m["code"] for m in ours["messages"]) == sorted(m["code"] for m in theirs["messages"])
    assert set(ours["infoCodes"]) <= set(theirs["infoCodes"])

    samples = [bvhio_joint_positions(tmp_path / f"crowd_{i:03}.bvh") for i in range(3)]
    count = len(samples[0][0])
    frames, times = frame_times(count, 30.0, [0, 7, count // 2, -1])
    three = node("three_positions.mjs", glb, ",".join(map(str, times)))
    assert [a["name"] for a in three["animations"]][1:] == ["sample_000", "sample_001", "sample_002"]
    # The character's still bones at its End Sites are not joints of the model.
    end_bones = sum(bool(re.search(r"_end$", b)) for b in three["bones"])
    for i, (positions, names) in enumerate(samples):
        height = float(np.ptp(positions[..., 1], axis=1).mean())
        worst = compare(three, 1 + i, positions, names, frames, np.eye(3), 1.0, height, missing=end_bones)
        assert worst <= 1e-5, f"sample {i}: worst {worst:.2e} of the height"


WALK_2S = FIXTURES / "human_walk_cmu_131_01_2s.bvh"


def printed_map(stderr):
    """The bone map `--retarget` prints: the lines after its header, `character: joint`."""
    lines = stderr.split("# sinmdm bone map", 1)[1].splitlines()[1:]
    return dict(line.split(": ", 1) for line in lines if ": " in line and not line.startswith(" "))


@pytest.mark.parametrize("rig,retarget,hips", [
    ("human_walk_rig_other_proportions.glb", [], "Hips"),
    ("human_walk_rig_unreal_names.glb", ["--retarget", "auto"], "pelvis"),
], ids=["other proportions, A pose, rolls", "Unreal names"])
def test_a_retargeted_walk_plays_in_three_pointing_where_bvhio_points(tmp_path, rig, retarget, hips):
    """`convert --mesh-from` onto Blender's reshaped rigs (legs 1.2x, arms 0.85x, an A pose,
    rolled bones; then Unreal names): the validator finds nothing the character lacks, and in
    three.js every paired bone points, at every frame, within 1 degree of where its joint
    points in bvhio's play of the clip, and the hips stand 1.2x as high above the ground."""
    character, glb = FIXTURES / rig, tmp_path / "retargeted.glb"
    done = run("convert", WALK_2S, "-o", glb, "--mesh-from", character, *retarget)
    pairs = printed_map(done.stderr)
    assert pairs[hips] == "Hips" and len(pairs) >= 25, pairs

    report = node("validate.mjs", character, glb)
    ours, theirs = report[str(glb)], report[str(character)]
    assert ours["errors"] == 0
    assert sorted(m["code"] for m in ours["messages"]) == sorted(m["code"] for m in theirs["messages"])
    assert set(ours["infoCodes"]) <= set(theirs["infoCodes"])

    positions, names = bvhio_joint_positions(WALK_2S)
    fps = bvh_fps(WALK_2S)
    frames, times = frame_times(len(positions), fps, list(range(len(positions))))
    three = node("three_positions.mjs", glb, ",".join(map(str, times)))
    played = np.asarray(three["positions"][0])
    height = float(np.ptp(positions[..., 1], axis=1).mean())
    bone = {name: i for i, name in enumerate(three["bones"])}
    joint = {name: i for i, name in enumerate(names)}
    parent = dict(zip(three["bones"], three["parents"]))

    def paired_ancestor(name):
        at = parent[name]
        while at is not None and at not in pairs:
            at = parent[at]
        return at

    worst, compared = 0.0, 0
    for target, source in pairs.items():
        above = paired_ancestor(target)
        if above is None or pairs[above] == source:
            continue
        u = played[:, bone[target]] - played[:, bone[above]]
        v = positions[frames][:, joint[source]] - positions[frames][:, joint[pairs[above]]]
        if np.linalg.norm(v, axis=1).max() < 1e-4 * height:
            continue  # a joint on its parent (CMU's Chest2 and lowerneck): no direction
        compared += 1
        cos = np.sum(u * v, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        angles = np.degrees(np.arccos(np.clip(cos, -1, 1)))
        assert np.all(np.isfinite(angles)), (target, source)
        worst = max(worst, float(angles.max()))
    assert compared >= 15
    assert worst <= 1.0, f"a bone is {worst:.3f} degrees off its joint"

    def ground(points, chosen):
        return np.percentile(points[:, chosen, 1].min(axis=1), 5)

    ours_ground = ground(played, [bone[t] for t in pairs])
    clip_ground = ground(positions[frames], [joint[s] for s in pairs.values()])
    ratio = (played[:, bone[hips], 1] - ours_ground) / (positions[frames][:, joint["Hips"], 1] - clip_ground)
    assert np.all(np.abs(ratio / 1.2 - 1) <= 0.01), (ratio.min(), ratio.max())

"""The rule that reads the clip (train/src/choose/clip_rule/): the clip's own intra diversity the
trainer reads before training, against the benchmark's measure computed with numpy from the
features `sinmdm encode` writes, and the choice the default makes from it."""

import math
import re
import subprocess

import numpy as np
import pytest

from conftest import TRAIN, clips, default_config, encoded_clip, rust_constant

# The benchmark's window for the intra diversity; the rule's ladder of steps (step_ladder/).
LOCAL_WINDOW = 15
LADDER_STEPS = [50, 75, 100, 150, 200, 250, 300, 400, 600, 1000]
# The rungs at the faster learning rate, climbed where none of the others meets every goal.
FASTER_STEPS = [1000, 3000]


CALM_INTRA_BELOW = rust_constant("CALM_INTRA_BELOW")
VARIED_WINDOW = rust_constant("VARIED_WINDOW")
MANY_FEET = rust_constant("MANY_FEET")
MANY_FEET_WINDOW = rust_constant("MANY_FEET_WINDOW")
MANY_FEET_CHANNELS = rust_constant("MANY_FEET_CHANNELS")
MANY_FEET_STEPS = rust_constant("MANY_FEET_STEPS")
MANY_FEET_DROPOUT = rust_constant("MANY_FEET_DROPOUT")
# A step's cost grows with the QnA window k as OFFSET + k; steps fitted to a wider window are
# rounded down to whole units.
WINDOW_STEP_COST_OFFSET = rust_constant("WINDOW_STEP_COST_OFFSET")
FITTED_STEPS_ROUNDING = rust_constant("FITTED_STEPS_ROUNDING")
# The default's settings a varied clip on two feet keeps; its frames a step and most items; a
# varied clip's items come in multiples of BATCH_ITEMS_MULTIPLE.
DEFAULT_DROPOUT = default_config("model", "dropout")
DEFAULT_CHANNELS = default_config("model", "channels")
DEFAULT_STEPS = default_config("training", "steps")
FRAMES_PER_STEP = default_config("training", "frames_per_step")
BATCH_SIZE = default_config("training", "batch_size")
assert rust_constant("BATCH_ITEMS_MULTIPLE") == 2, "items_of below pairs a varied clip's items in twos"

def items_of(frames, paired):
    """The copies of a clip of `frames` frames in a step: round(1024 / frames) within 1..8, half
    away from zero as Rust rounds; a varied clip (`paired`) that fits the budget and would get an
    odd count of 3 or more gets the even neighbour whose frames come nearer 1 024 (the smaller on
    a tie)."""
    items = min(max(int(np.floor(FRAMES_PER_STEP / frames + 0.5)), 1), BATCH_SIZE)
    if not paired or frames > FRAMES_PER_STEP or items % 2 == 0 or items == 1:
        return items
    evens = [n for n in (items - 1, items + 1) if 2 <= n <= BATCH_SIZE]
    return min(evens, key=lambda n: (abs(n * frames - FRAMES_PER_STEP), n))


def numpy_intra_diversity(raw, columns):
    """Mean over every ordered pair of 15-frame windows of the clip's joint rotations and contact
    labels of their Frobenius distance divided by 15 (sinmdm_eval::intra_diversity)."""
    keep = [i for i, c in enumerate(columns) if ".rot6d[" in c or c.endswith(".contact")]
    x = np.asarray(raw, dtype=np.float64)[keep].T  # frames x metric columns
    starts = x.shape[0] - LOCAL_WINDOW + 1
    windows = np.stack([x[s:s + LOCAL_WINDOW].ravel() for s in range(starts)])
    sq = (windows ** 2).sum(axis=1)
    d2 = np.maximum(sq[:, None] + sq[None, :] - 2 * windows @ windows.T, 0.0)
    return float(np.sqrt(d2).mean() / LOCAL_WINDOW)


@pytest.mark.parametrize("clip", clips(), ids=lambda p: p.stem)
def test_the_default_reads_the_clip_as_numpy_does(clip, tmp_path, sinmdm):
    # The default's root layout, so that the root joint's rotation is read as the default reads it.
    doc = encoded_clip(clip, tmp_path, sinmdm, "\n  root_layout: auto\n")
    expected = numpy_intra_diversity(doc["samples"][0], doc["columns"])

    out = subprocess.run([str(TRAIN), str(clip), "--dry-run"], check=True, capture_output=True,
                         text=True).stdout
    found = re.search(r"clip +(calm|varied): its own intra diversity ([0-9.]+)", out)
    assert found, out
    assert abs(float(found.group(2)) - expected) < 0.0006, (found.group(2), expected)
    calm = expected < CALM_INTRA_BELOW
    assert found.group(1) == ("calm" if calm else "varied"), out
    window = re.search(r"receptive field \d+ frames \(QnA window (\d+)\)", out)
    steps = re.search(r"^steps +(?:up to )?(\d+) \(batch", out, re.M)
    channels = re.search(r"^channels C +(\d+)$", out, re.M)
    frames = int(re.search(r"\((\d+) frames at [0-9.]+ fps\)", out).group(1))
    batch = int(re.search(r"^steps +(?:up to )?\d+ \(batch (\d+) x", out, re.M).group(1))
    assert batch == items_of(frames, paired=not calm), (frames, out)
    # The window is the rule's, chosen from the clip: no hint second-guesses it.
    assert "hint" not in out, out
    # The feet the rule reads are the clip's contact columns, and they are the feet of the
    # animal the clip shows: two for a human, four for a dog or a fox (a running dog's nose and
    # the tail a dog lies on are chain ends that touch the ground now and then, not feet).
    feet_line = re.search(r"^feet +(\d+) \(([^)]*)\)", out, re.M)
    assert feet_line, out
    named = feet_line.group(2).split(", ")
    contact = [c[: -len(".contact")] for c in doc["columns"] if c.endswith(".contact")]
    assert sorted(named) == sorted(contact) and int(feet_line.group(1)) == len(contact), out
    animal = clip.stem.split("_")[0]
    assert len(contact) == {"human": 2, "dog": 4, "fox": 4}[animal], (clip.stem, contact)
    if calm:
        # A calm clip's steps are chosen when training starts, by the step ladder: the dry run
        # names its rungs and trains none of them.
        assert "chosen by the step ladder" in out, out
        rungs = ", ".join(map(str, LADDER_STEPS[:-1])) + f" and {LADDER_STEPS[-1]}"
        assert f"short runs of {rungs} steps" in out, out
        assert "and of 1000 and 3000 steps at learning rate 0.001" in out, out
        assert int(steps.group(1)) == max(LADDER_STEPS + FASTER_STEPS), out
        assert window.group(1) == "3", out
        assert int(channels.group(1)) == DEFAULT_CHANNELS, out
    else:
        # The feet are the clip's contact labels, one column each in the features.
        feet = sum(c.endswith(".contact") for c in doc["columns"])
        if feet >= MANY_FEET:
            assert window.group(1) == str(MANY_FEET_WINDOW), out
            assert int(channels.group(1)) == MANY_FEET_CHANNELS, out
            assert int(steps.group(1)) == MANY_FEET_STEPS, out
            assert f"dropout         {MANY_FEET_DROPOUT}: on {feet} feet" in out, out
        else:
            assert window.group(1) == str(VARIED_WINDOW), out
            assert int(channels.group(1)) == DEFAULT_CHANNELS, out
            assert int(steps.group(1)) == DEFAULT_STEPS, out
            assert f"dropout         {DEFAULT_DROPOUT} (the configuration's)" in out, out


def window_at_fps(window, fps):
    """The QnA window that keeps the receptive field's seconds at `fps` (docs/SPEC.md, the
    network's shape): the receptive half-width 8 + 3 (k - 1) / 2 grows by fps / 30."""
    half = 8 + 3 * (window - 1) // 2
    wanted = half * max(fps / 30.0, 1.0)
    return 2 * max(int(np.floor((wanted - 8) / 3 + 0.5)), window // 2) + 1


@pytest.mark.parametrize("rate", [60, 120])
def test_a_varied_clip_above_30_fps_trains_the_steps_that_fit_the_same_time(rate):
    # The CMU hop is varied and captured at 120 fps: learned at 60 or 120 fps, its window follows
    # the frame rate and its steps fall so that (10 + k) x steps stays within the 30 fps run's.
    clip = [c for c in clips() if c.name == "human_hop_cmu_131_03.bvh"][0]
    out = subprocess.run([str(TRAIN), str(clip), "--fps", str(rate), "--dry-run"], check=True,
                         capture_output=True, text=True).stdout
    assert re.search(r"clip +varied", out), out
    trained = window_at_fps(VARIED_WINDOW, rate)
    window = re.search(r"receptive field (\d+) frames \(QnA window (\d+)\)", out)
    assert int(window.group(2)) == trained, out
    assert int(window.group(1)) == 14 + 3 * trained, out
    steps = int(re.search(r"^steps +(\d+) \(batch", out, re.M).group(1))
    budget = DEFAULT_STEPS * (WINDOW_STEP_COST_OFFSET + VARIED_WINDOW)
    cost = WINDOW_STEP_COST_OFFSET + trained
    assert steps % FITTED_STEPS_ROUNDING == 0, out
    assert steps * cost <= budget < (steps + FITTED_STEPS_ROUNDING) * cost, (steps, out)
    assert f"at {rate} fps the window is {trained}" in out, out
    assert f"meant at 30 fps, {DEFAULT_STEPS} (the configuration's)" in out, out


def test_a_varied_clip_whose_copies_would_be_odd_trains_them_in_pairs():
    # The CMU hop learned at 40 fps is 368 frames: round(1024 / 368) = 3 copies a step, two on one
    # core and one on the other; 2 copies (736 frames) come nearer 1 024 than 4 (1 472).
    clip = [c for c in clips() if c.name == "human_hop_cmu_131_03.bvh"][0]
    out = subprocess.run([str(TRAIN), str(clip), "--fps", "40", "--dry-run"], check=True,
                         capture_output=True, text=True).stdout
    assert re.search(r"clip +varied", out), out
    frames = int(re.search(r"\((\d+) frames at 40 fps\)", out).group(1))
    assert frames == 368, out
    assert items_of(frames, paired=False) == 3 and items_of(frames, paired=True) == 2
    assert re.search(r"^steps +\d+ \(batch 2 x the whole clip\)", out, re.M), out
    assert re.search(r"batch +2 items of the clip's 368 frames, 736 frames a step: the "
                     r"configuration's 1024 would make 3", out), out


def lying_dog_bvh(lying, standing):
    """A four-legged figure (Y-up) that lies for `lying` frames, its legs folded forward at its
    hips' height (6 over the floor) and its tail sloping down to the floor, then stands for
    `standing` frames on its four paws (End Sites on the floor), hips 32 up, tail level."""
    legs = [("FrontLeft", 8, 20), ("FrontRight", -8, 20), ("HindLeft", 8, -20), ("HindRight", -8, -20)]
    rot = "CHANNELS 3 Zrotation Xrotation Yrotation"
    lines = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
             "JOINT Neck", "{", "OFFSET 0 10 25", rot, "End Site", "{", "OFFSET 0 5 0", "}", "}"]
    for name, x, z in legs:
        lines += [f"JOINT {name}UpLeg", "{", f"OFFSET {x} 0 {z}", rot,
                  f"JOINT {name}Leg", "{", "OFFSET 0 -15 0", rot,
                  f"JOINT {name}Paw", "{", "OFFSET 0 -15 0", rot,
                  "End Site", "{", "OFFSET 0 -2 0", "}", "}", "}", "}"]
    lines += ["JOINT Tail", "{", "OFFSET 0 0 -20", rot, "JOINT Tail1", "{", "OFFSET 0 0 -20", rot,
              "End Site", "{", "OFFSET 0 0 -5", "}", "}", "}", "}"]
    # The Tail joint sits 20 behind the hips at their height; turned down by asin(6 / 25), what
    # hangs from it (Tail1 20 and its End Site 5) brings the tail's end to the floor.
    tail_down = -math.degrees(math.asin(6 / 25))
    # Hips (6 channels), neck, then each leg's UpLeg (turned -90 about X: the leg points
    # forward), Leg and Paw, then Tail and Tail1.
    lie = [0, 6, 0, 0, 0, 0] + [0, 0, 0] + ([0, -90, 0] + [0, 0, 0] * 2) * 4 + [0, tail_down, 0, 0, 0, 0]
    stand = [0, 32, 0, 0, 0, 0] + [0, 0, 0] * 15
    lines += ["MOTION", f"Frames: {lying + standing}", "Frame Time: 0.0333333"]
    lines += [" ".join(f"{v:.6f}" for v in (lie if f < lying else stand))
              for f in range(lying + standing)]
    return "\n".join(lines) + "\n"


def test_a_figure_that_lies_most_of_the_clip_stands_on_its_paws(tmp_path, sinmdm):
    # Lying for 80 frames of 100, the tail is the frame's lowest point in 80 and the folded paws
    # are 6 over the floor (the height is about 26, the tolerance 0.05 of it); standing for 20,
    # the paws are on the floor. Over every frame the tail would be the one chain end at the
    # ground in a quarter of them (80 against the paws' 20); over the frames the figure stands
    # in (its hips 32 up, against 6 lying: under 0.35 of that), the paws are, in all of them.
    clip = tmp_path / "lying_dog.bvh"
    clip.write_text(lying_dog_bvh(80, 20))
    out = sinmdm("inspect", clip, "--up", "y")
    contacts = re.search(r"^contacts +(.*) \(in contact", out, re.M)
    assert contacts, out
    named = [part.rsplit(" ", 1)[0] for part in contacts.group(1).split(", ")]
    assert sorted(named) == sorted(f"{leg}Paw" for leg in
                                   ("FrontLeft", "FrontRight", "HindLeft", "HindRight")), out

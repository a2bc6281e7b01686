"""Masks, spans and the task plans of SPEC section 5 (runtime/src/tasks/)."""

import numpy as np

from .features import root_rows
from .schedule import Schedule

INBETWEEN_RAMP = 10
EXPAND_RAMP = 6
HARMONIZE_FACTOR = 2
HARMONIZE_FREE_SHARE = 0.02
MAX_SAMPLE_FRAMES = 100_000
MAX_SAMPLES = 1024


class TaskError(ValueError):
    """A request that cannot run."""


def parse_position(text, fps):
    """Frames ('120') or seconds ('4s')."""
    text = text.strip()
    if text.endswith("s"):
        seconds = float(text[:-1])
        if not seconds >= 0:
            raise TaskError(f"'{text}': seconds must be 0 or more")
        return int(np.floor(seconds * fps + 0.5))
    return int(text)


def parse_span(text, fps, frames):
    """START:END, END exclusive, empty END = frames."""
    a, b = text.split(":", 1)
    start = parse_position(a, fps) if a.strip() else 0
    end = parse_position(b, fps) if b.strip() else frames
    return (start, end)


def check_spans(spans, frames):
    spans = sorted(spans)
    for s in spans:
        if s[1] <= s[0]:
            raise TaskError(f"span {s[0]}:{s[1]} is empty")
        if s[1] > frames:
            raise TaskError(f"span {s[0]}:{s[1]} reaches past the reference's {frames} frames")
    for a, b in zip(spans, spans[1:]):
        if b[0] < a[1]:
            raise TaskError(f"spans {a[0]}:{a[1]} and {b[0]}:{b[1]} overlap")
    return spans


def covered(n, spans):
    keep = np.zeros(n, dtype=bool)
    for start, end in spans:
        keep[min(start, n) : min(end, n)] = True
    return keep


def soft_mask(keep, ramp):
    """0 outside, min(d, ramp) / ramp inside, d = frames to the nearest gap (1 next to it)."""
    n = len(keep)
    ramp = max(ramp, 1)
    gaps = np.flatnonzero(~keep)
    out = np.zeros(n, dtype=np.float32)
    for i in range(n):
        if not keep[i]:
            continue
        d = int(np.min(np.abs(gaps - i))) if len(gaps) else ramp
        out[i] = np.float32(min(d, ramp)) / np.float32(ramp)
    return out


def joint_of_columns(layout):
    """The joint index of every feature column."""
    joints = []
    root = layout.get("root")
    if root:
        joints += [root["joint"]] * root_rows(layout)
    for j in layout["rotation_joints"]:
        joints += [j] * 6
    joints += [j for j, _ in layout["position_channels"]]
    joints += list(layout["contact_joints"])
    return joints


def joints_by_name(layout, names):
    index = {j["name"]: i for i, j in enumerate(layout["skeleton"]["joints"])}
    out = []
    for name in names:
        if name not in index:
            raise TaskError(f"joint '{name}' is not in the model's skeleton")
        out.append(index[name])
    return out


def subtree(layout, joint):
    joints = layout["skeleton"]["joints"]
    inside = [False] * len(joints)
    inside[joint] = True
    for j in range(joint + 1, len(joints)):
        p = joints[j]["parent"]
        if p is not None:
            inside[j] = inside[p]
    return [j for j in range(len(joints)) if inside[j]]


def schedule_for(model, steps):
    total = model.metadata["diffusion"]["steps"]
    return Schedule.cosine(total) if steps is None else Schedule.respaced(total, steps)


def plan_inbetween(model, reference, keep, ramp=INBETWEEN_RAMP):
    y = model.normalize(reference)
    n = y.shape[1]
    if not keep:
        raise TaskError("in-betweening needs at least one span of the reference to keep")
    weights = soft_mask(covered(n, check_spans(keep, n)), ramp)
    mask = np.broadcast_to(weights, y.shape).astype(np.float32)
    return n, (y, mask)


def plan_expand(model, reference, prefix, suffix, ramp=EXPAND_RAMP):
    y = model.normalize(reference)
    if prefix + suffix == 0:
        raise TaskError("expansion needs a prefix or a suffix of at least one frame")
    n = prefix + y.shape[1] + suffix
    padded = np.zeros((y.shape[0], n), dtype=np.float32)
    padded[:, prefix : prefix + y.shape[1]] = y
    weights = soft_mask(covered(n, [(prefix, prefix + y.shape[1])]), ramp)
    return n, (padded, np.broadcast_to(weights, padded.shape).astype(np.float32))


def plan_compose(model, reference, joints, root, spans, ramp=INBETWEEN_RAMP):
    y = model.normalize(reference)
    n = y.shape[1]
    layout = model.layout
    owner = joint_of_columns(layout)
    chosen = set(joints)
    rows = {r for r, j in enumerate(owner) if j in chosen}
    if root and layout.get("root"):
        rows |= set(range(root_rows(layout)))
    if not rows:
        raise TaskError("composition needs joints or the root to take from the reference")
    weights = np.ones(n, dtype=np.float32) if not spans else soft_mask(covered(n, check_spans(spans, n)), ramp)
    mask = np.zeros(y.shape, dtype=np.float32)
    for r in sorted(rows):
        mask[r] = weights
    return n, (y, mask)


def plan_harmonize(model, content, factor=HARMONIZE_FACTOR, free_share=HARMONIZE_FREE_SHARE):
    y = model.normalize(content)
    if factor < 1 or factor > max(y.shape[1], 1):
        raise TaskError(f"the down-sampling factor must be between 1 and {y.shape[1]}, got {factor}")
    if not 0.0 <= free_share <= 1.0:
        raise TaskError(f"the free share must be between 0 and 1, got {free_share}")
    return y.shape[1], (y, factor, free_share)


DANCE_TEMPO_RANGE = (0.75, 1.25)
DANCE_HOLD = 12
DANCE_RAMP = 13
DANCE_ORDER_STREAM = 3_000_000


def _median_interval(beats):
    gaps = sorted(b - a for a, b in zip(beats, beats[1:]))
    return float(gaps[len(gaps) // 2])


def _check_beats(beats, frames, what):
    if len(beats) < 2:
        raise TaskError(f"{what} need at least two beats to have a tempo, got {len(beats)}")
    for a, b in zip(beats, beats[1:]):
        if b <= a:
            raise TaskError(f"{what} must increase: frame {b} comes after frame {a}")
    if beats[-1] >= frames:
        raise TaskError(f"{what} reach frame {beats[-1]}, past the {frames} frames they belong to")


def _beats_at_level(level, beats):
    if level in ("auto", "every"):
        return list(beats)
    if level == "every-other":
        return list(beats[::2])
    out = []
    for a, b in zip(beats, beats[1:]):
        out.append(a)
        mid = (a + b) // 2
        if mid > a:
            out.append(mid)
    out.append(beats[-1])
    return out


def keyframe_order(usable, count, order, seed):
    """Passes over the usable reference beats, in order or each shuffled (Fisher-Yates from
    the portable words of DANCE_ORDER_STREAM), as runtime/src/tasks/dance.rs."""
    from .noise import _words
    out = []
    cycle = 0
    while len(out) < count:
        p = list(range(usable))
        if order == "shuffled" and usable > 1:
            words = _words(seed, DANCE_ORDER_STREAM, (cycle + 1) * usable)
            for i in range(usable - 1, 0, -1):
                # Word index cycle * usable + i is element cycle * usable + i of 0-based words.
                j = int(words[cycle * usable + i]) % (i + 1)
                p[i], p[j] = p[j], p[i]
        out.extend(p[: count - len(out)])
        cycle += 1
    return out


def place_keyframes(reference_frames, reference_beats, target_beats, frames, hold, ramp, order,
                    level, seed):
    """(level, ratio, hold, ramp, [(target, reference)]) of a dance."""
    _check_beats(reference_beats, reference_frames, "the reference's beats")
    _check_beats(target_beats, frames, "the music's beats")
    ref_interval = _median_interval(reference_beats)
    levels = ["every", "every-other", "half"] if level == "auto" else [level]
    best = None
    for lv in levels:
        beats = _beats_at_level(lv, target_beats)
        if len(beats) < 2:
            continue
        ratio = _median_interval(beats) / ref_interval
        if best is None or abs(np.log(ratio)) < abs(np.log(best[2])):
            best = (lv, beats, ratio)
    if best is None:
        raise TaskError(f"the music's beats at level {level} leave fewer than two beats")
    lv, beats, ratio = best
    low, high = DANCE_TEMPO_RANGE
    if not low <= ratio <= high:
        raise TaskError(f"the music's beats are {ratio:.2f}x the reference's; the model learned {low}-{high}x")
    closest = min(b - a for a, b in zip(beats, beats[1:]))
    hold = min(hold, max(closest - 2, 0) // 2)
    ramp = min(ramp, hold + 1)
    usable = [r for r in reference_beats if r >= hold and r + hold < reference_frames]
    if not usable:
        raise TaskError(f"no beat of the reference has {hold} frames on both sides")
    picks = keyframe_order(len(usable), len(beats), order, seed)
    return lv, ratio, hold, ramp, [(t, usable[k]) for t, k in zip(beats, picks)]


def plan_dance(model, reference, reference_beats, target_beats, frames, hold=DANCE_HOLD,
               ramp=DANCE_RAMP, order="shuffled", level="auto", root=True, seed=0):
    if hold < 0 or ramp < 0 or min(list(reference_beats) + list(target_beats) + [0]) < 0:
        raise TaskError("hold, ramp and beat frames must not be negative")
    if ramp > MAX_SAMPLE_FRAMES:
        raise TaskError(f"a ramp of {ramp} frames is too wide")
    y = model.normalize(reference)
    if not 1 <= frames <= MAX_SAMPLE_FRAMES:
        raise TaskError(f"a sample of {frames} frames is not possible")
    _, _, h, ramp, keys = place_keyframes(y.shape[1], reference_beats, target_beats, frames, hold,
                                          ramp, order, level, seed)
    target = np.zeros((y.shape[0], frames), dtype=np.float32)
    keep = np.zeros(frames, dtype=bool)
    for t, r in keys:
        for u in range(max(t - h, 0), min(t + h, frames - 1) + 1):
            target[:, u] = y[:, r + u - t]
            keep[u] = True
    weights = soft_mask(keep, ramp)
    rows_of_root = root_rows(model.layout)
    mask = np.zeros(target.shape, dtype=np.float32)
    first = 0 if root else rows_of_root
    mask[first:] = weights
    return frames, (target, mask)

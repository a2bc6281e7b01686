"""Streams (runtime/src/stream): endless motion in fixed blocks, each an in-betweening run seeded
from the stream's seed and the block's index, whose window starts with the last C final frames
of the block before (kept exactly) and the R frames it held back (kept with a soft border).
Only the features are reproduced; decoding and foot planting are post-processes."""

import numpy as np

from .noise import _words
from .sampler import sample
from .steer import integrate, mat_vec, plan_steering, start_course, yaw
from .tasks import INBETWEEN_RAMP, soft_mask

BLOCK_SEED_STREAM = 2_000_000


def block_seed(seed, index):
    return int(_words(seed, BLOCK_SEED_STREAM, index + 1)[index])


def window(context, ramp, block, index):
    """(start, frames, carried, context) of block `index`'s window."""
    if index == 0:
        return 0, block + ramp, 0, 0
    return index * block - context, context + ramp + block, context + ramp, context


def stream_features(model, schedule, seed, total, block=None, context=None, ramp=INBETWEEN_RAMP,
                    method=("ancestral",), commands=None):
    """Raw features [F, total] of the first `total` frames of a stream; `commands` (per stream
    frame, as `steer.plan_steering` takes them) steer a heading-relative model."""
    context = context or max(model.metadata["network"]["receptive_field"], 1)
    block = block or max(model.metadata["training"]["clip_frames"], context)
    ramp = max(ramp, 1)
    f = model.features
    out = np.zeros((f, total), dtype=np.float32)
    carried = None
    last_course = None
    made, index = 0, 0
    while made < total:
        start, n, carry, ctx = window(context, ramp, block, index)
        steering = None
        if commands:
            if last_course is not None and ctx > 0:
                anchor, course = ctx - 1, last_course
            else:
                anchor, course = 0, start_course(model)
            frames = [commands[i] if i < len(commands) else None for i in range(start, start + n)]
            steering = plan_steering(model, frames, anchor, course, ramp)
        inpainting = None
        if carried is not None:
            reference = np.zeros((f, n), dtype=np.float32)
            reference[:, :carry] = carried
            weights = soft_mask(np.arange(n) < carry, ramp)
            mask = np.repeat(weights[None, :], f, axis=0).astype(np.float32)
            inpainting = (reference, mask)
        x = sample(model, schedule, 1, n, block_seed(seed, index), inpainting, method=method,
                   steering=steering)[0]
        carried = x[:, n - (context + ramp):].copy()
        raw = model.denormalize(x)
        if model.layout["root"] and model.layout["root"].get("heading"):
            last_course = _course_after(model, raw, ctx, block, last_course)
        take = min(block, total - made)
        out[:, made:made + take] = raw[:, ctx:ctx + take]
        made += take
        index += 1
    return out


def _course_after(model, raw, ctx, block, last):
    """The root's canonical position and facing at the block's last final frame: the block's
    course from the start that puts its frame ctx - 1 at the last block's end (Stream's
    complete_block)."""
    rows = raw[:, :ctx + block]
    root, heading = start_course(model)
    if last is not None and ctx > 0:
        positions, headings = integrate(rows, root, heading)
        k = ctx - 1
        turn = last[1] - headings[k]
        travelled = [positions[k][c] - root[c] for c in range(3)]
        travelled[1] = 0.0
        turned = mat_vec(yaw(turn), travelled)
        start = ([last[0][c] - turned[c] for c in range(3)], heading + turn)
    else:
        start = (root, heading)
    positions, headings = integrate(rows, *start)
    return positions[-1], headings[-1]

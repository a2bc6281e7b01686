"""Streams (runtime/src/stream): endless motion in fixed blocks, each an in-betweening run seeded
from the stream's seed and the block's index, whose window starts with the last C final frames
of the block before (kept exactly) and the R frames it held back (kept with a soft border).
Only the features are reproduced; decoding and foot planting are post-processes."""

import numpy as np

from .noise import _words
from .sampler import sample
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
                    method=("ancestral",)):
    """Raw features [F, total] of the first `total` frames of a stream."""
    context = context or max(model.metadata["network"]["receptive_field"], 1)
    block = block or max(model.metadata["training"]["clip_frames"], context)
    ramp = max(ramp, 1)
    f = model.features
    out = np.zeros((f, total), dtype=np.float32)
    carried = None
    made, index = 0, 0
    while made < total:
        _, n, carry, ctx = window(context, ramp, block, index)
        inpainting = None
        if carried is not None:
            reference = np.zeros((f, n), dtype=np.float32)
            reference[:, :carry] = carried
            weights = soft_mask(np.arange(n) < carry, ramp)
            mask = np.repeat(weights[None, :], f, axis=0).astype(np.float32)
            inpainting = (reference, mask)
        x = sample(model, schedule, 1, n, block_seed(seed, index), inpainting, method=method)[0]
        carried = x[:, n - (context + ramp):].copy()
        raw = model.denormalize(x)
        take = min(block, total - made)
        out[:, made:made + take] = raw[:, ctx:ctx + take]
        made += take
        index += 1
    return out

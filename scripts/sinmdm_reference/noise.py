"""The portable noise generator (SPEC section 7), bit-for-bit equal to runtime/src/diffusion/noise.rs."""

import numpy as np

INITIAL_NOISE_STREAM = 0
HARMONIZE_STREAM_BASE = 1_000_000

_MASK = (1 << 64) - 1
_GOLDEN = 0x9E3779B97F4A7C15
_STREAM_MIX = 0xD1B54A32D192ED03


def _words(seed, stream, count):
    """Words 0..count-1 of a stream as uint64, with numpy's wrapping uint64 arithmetic."""
    base = np.uint64((seed ^ (stream * _STREAM_MIX)) & _MASK)
    index = np.arange(1, count + 1, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = base + index * np.uint64(_GOLDEN)
        z ^= z >> np.uint64(30)
        z *= np.uint64(0xBF58476D1CE4E5B9)
        z ^= z >> np.uint64(27)
        z *= np.uint64(0x94D049BB133111EB)
        z ^= z >> np.uint64(31)
    return z


def uniforms(seed, stream, count):
    """Uniform numbers in (0, 1]: ((word >> 11) + 1) * 2**-53, in float64."""
    words = _words(seed, stream, count)
    return ((words >> np.uint64(11)) + np.uint64(1)).astype(np.float64) * 2.0**-53


def normals(seed, stream, count):
    """The first `count` normals of a stream (Box-Muller in float64, then float32)."""
    pairs = (count + 1) // 2
    u = uniforms(seed, stream, 2 * pairs).reshape(pairs, 2)
    r = np.sqrt(-2.0 * np.log(u[:, 0]))
    angle = 2.0 * np.pi * u[:, 1]
    out = np.stack([r * np.cos(angle), r * np.sin(angle)], axis=1).reshape(-1)
    return out[:count].astype(np.float32)

"""Ancestral DDPM sampling with mask blending and harmonization (runtime/src/diffusion/sampler.rs).

Every array operation is float32, in the same order as the Rust loop; coefficients are float64
rounded once to float32.
"""

import math

import numpy as np

from .noise import HARMONIZE_STREAM_BASE, INITIAL_NOISE_STREAM, normals


def downsample(x, factor):
    """Average of each group of `factor` frames along the last axis (the last group may be shorter)."""
    n = x.shape[-1]
    m = -(-n // factor)
    out = np.empty(x.shape[:-1] + (m,), dtype=np.float32)
    for j in range(m):
        group = x[..., j * factor : min((j + 1) * factor, n)]
        total = np.zeros(x.shape[:-1], dtype=np.float32)
        for i in range(group.shape[-1]):
            total = total + group[..., i]
        out[..., j] = total / np.float32(group.shape[-1])
    return out


def upsample(z, factor, n):
    """Linear interpolation to n frames: frame i reads u = (i + 0.5) / factor - 0.5, clamped."""
    m = z.shape[-1]
    out = np.empty(z.shape[:-1] + (n,), dtype=np.float32)
    for i in range(n):
        u = min(max((i + 0.5) / factor - 0.5, 0.0), float(m - 1))
        i0 = int(np.floor(u))
        i1 = min(i0 + 1, m - 1)
        w = np.float32(u - i0)
        out[..., i] = z[..., i0] * (np.float32(1.0) - w) + z[..., i1] * w
    return out


def low_pass(x, factor):
    return upsample(downsample(x, factor), factor, x.shape[-1])


def _noise(seed, stream, shape):
    return normals(seed, stream, int(np.prod(shape))).reshape(shape)


def coefficients(method, schedule, k):
    """(c_x0, c_xt, c_prev, sigma) of step index k (runtime/src/diffusion/method.rs).

    method: ("ancestral",), ("ddim", eta) or ("dpm2m",)."""
    a, p = schedule.alphas_cumprod[k], schedule.alphas_cumprod_prev[k]
    if method[0] == "ancestral":
        c0, ct = schedule.posterior_mean_coefficients(k)
        return c0, ct, 0.0, schedule.posterior_std(k) if k > 0 else 0.0
    if method[0] == "ddim":
        eta = method[1]
        sigma = eta * math.sqrt((1.0 - p) / (1.0 - a)) * math.sqrt(1.0 - a / p) if k > 0 else 0.0
        ct = math.sqrt(max(1.0 - p - sigma * sigma, 0.0)) / math.sqrt(1.0 - a)
        return math.sqrt(p) - ct * math.sqrt(a), ct, 0.0, sigma
    if method[0] == "dpm2m":
        if k == 0:
            return 1.0, 0.0, 0.0, 0.0

        def lam(abar):
            return 0.5 * math.log(abar / (1.0 - abar))

        h = lam(p) - lam(a)
        m = math.sqrt(p) * (1.0 - math.exp(-h))
        ct = math.sqrt((1.0 - p) / (1.0 - a))
        if k == len(schedule.timesteps) - 1:
            return m, ct, 0.0, 0.0
        r = (lam(a) - lam(schedule.alphas_cumprod[k + 1])) / h
        return m * (1.0 + 0.5 / r), ct, -m * 0.5 / r, 0.0
    raise ValueError(f"unknown sampling method {method[0]}")


def sample(model, schedule, batch, frames, seed, inpainting=None, harmonization=None, progress=None,
           method=("ancestral",), steering=None):
    """Normalised features [B, F, N].

    inpainting: (reference [F, N], mask [F, N]) normalised; harmonization: (content [F, N],
    factor, free_share); method as in `coefficients`; steering: a `steer.Steering`, applied to
    each sample's prediction before the mask blending."""
    shape = (batch, model.features, frames)
    steps = len(schedule.timesteps)
    free = int(np.floor(harmonization[2] * steps + 0.5)) if harmonization else 0
    one = np.float32(1.0)
    x = _noise(seed, INITIAL_NOISE_STREAM, shape)
    x0_prev = None
    for step in range(steps):
        k = steps - 1 - step
        t = np.full(batch, schedule.timesteps[k], dtype=np.int64)
        x0 = model.denoise(x, t)
        if steering is not None:
            x0 = np.array(x0, dtype=np.float32)
            for b in range(batch):
                steering.apply(x0[b])
        if inpainting is not None:
            y, m = inpainting
            x0 = x0 * (one - m) + y * m
        c0, ct, cp, sigma = coefficients(method, schedule, k)
        x = np.float32(c0) * x0 + np.float32(ct) * x
        if k > 0 and sigma > 0.0:
            x = x + np.float32(sigma) * _noise(seed, step + 1, shape)
        elif cp != 0.0 and x0_prev is not None:
            x = x + np.float32(cp) * x0_prev
        if method[0] == "dpm2m":
            x0_prev = x0
        if harmonization is not None and step < steps - free:
            content, factor, _ = harmonization
            a, s = schedule.q_sample_coefficients(k - 1) if k > 0 else (1.0, 0.0)
            noisy = np.float32(a) * content + np.float32(s) * _noise(seed, HARMONIZE_STREAM_BASE + step + 1, shape)
            ours = low_pass(x, factor)
            theirs = low_pass(noisy, factor)
            x = x - ours + theirs
        if progress:
            progress(step + 1, steps)
    return x

"""The diffusion schedule (SPEC section 4), equal to runtime/src/diffusion/schedule.rs."""

import math

import numpy as np

DEFAULT_DIFFUSION_STEPS = 1000
MAX_BETA = 0.999


def cosine_alpha_bar(s):
    """abar(s) = cos^2(((s + 0.008) / 1.008) * pi / 2)."""
    return math.cos(((s + 0.008) / 1.008) * math.pi / 2) ** 2


class Schedule:
    """Kept steps `timesteps` (original t fed to the network) with their betas and abar."""

    def __init__(self, timesteps, betas):
        self.timesteps = list(timesteps)
        self.betas = np.asarray(betas, dtype=np.float64)
        self.alphas_cumprod = np.cumprod(1.0 - self.betas)
        self.alphas_cumprod_prev = np.concatenate([[1.0], self.alphas_cumprod[:-1]])

    @staticmethod
    def cosine(steps=DEFAULT_DIFFUSION_STEPS):
        if steps < 2:
            raise ValueError(f"the diffusion needs at least 2 steps, got {steps}")
        betas = [
            min(1.0 - cosine_alpha_bar((i + 1) / steps) / cosine_alpha_bar(i / steps), MAX_BETA)
            for i in range(steps)
        ]
        return Schedule(range(steps), betas)

    @staticmethod
    def respaced(steps, kept):
        full = Schedule.cosine(steps)
        if kept < 2 or kept > steps:
            raise ValueError(f"sampling steps must be between 2 and {steps}, got {kept}")
        if kept == steps:
            return full
        t1, s1 = steps - 1, kept - 1
        timesteps = [(2 * k * t1 + s1) // (2 * s1) for k in range(kept)]
        betas, previous = [], 1.0
        for t in timesteps:
            abar = full.alphas_cumprod[t]
            betas.append(1.0 - abar / previous)
            previous = abar
        return Schedule(timesteps, betas)

    def posterior_mean_coefficients(self, k):
        beta, abar, prev = self.betas[k], self.alphas_cumprod[k], self.alphas_cumprod_prev[k]
        return beta * math.sqrt(prev) / (1.0 - abar), (1.0 - prev) * math.sqrt(1.0 - beta) / (1.0 - abar)

    def posterior_variance(self, k):
        return self.betas[k] * (1.0 - self.alphas_cumprod_prev[k]) / (1.0 - self.alphas_cumprod[k])

    def posterior_std(self, k):
        var = self.posterior_variance(min(1, len(self.betas) - 1) if k == 0 else k)
        return math.exp(0.5 * math.log(var))

    def q_sample_coefficients(self, k):
        """(sqrt(abar_k), sqrt(1 - abar_k))."""
        abar = self.alphas_cumprod[k]
        return math.sqrt(abar), math.sqrt(1.0 - abar)

"""The Python reference's noise and schedule against published values and the SPEC formulas."""

import math
import sys

import numpy as np

from conftest import ROOT

from sinmdm_reference import noise, schedule


def test_noise_matches_the_published_values():
    expected = np.array([0.41471976, 0.65268123, -0.89188623, 1.3268336], dtype=np.float32)
    assert np.array_equal(noise.normals(42, 0, 4), expected)


def test_odd_counts_are_prefixes_and_streams_differ():
    assert np.array_equal(noise.normals(7, 3, 5), noise.normals(7, 3, 6)[:5])
    assert not np.array_equal(noise.normals(42, 0, 8), noise.normals(42, 1, 8))
    assert not np.array_equal(noise.normals(42, 0, 8), noise.normals(42, 1_000_001, 8))


def test_schedule_telescopes_and_respaces():
    full = schedule.Schedule.cosine(1000)
    for n in (0, 10, 500, 980):
        want = schedule.cosine_alpha_bar((n + 1) / 1000) / schedule.cosine_alpha_bar(0.0)
        assert abs(full.alphas_cumprod[n] - want) < 1e-12
    four = schedule.Schedule.respaced(1000, 4)
    assert four.timesteps == [0, 333, 666, 999]
    assert np.allclose(four.alphas_cumprod, full.alphas_cumprod[[0, 333, 666, 999]], atol=1e-12)
    assert schedule.Schedule.respaced(1000, 50).timesteps[1] == 20
    c0, ct = full.posterior_mean_coefficients(500)
    abar, prev = full.alphas_cumprod[500], full.alphas_cumprod[499]
    assert abs(c0 + ct * math.sqrt(abar) - math.sqrt(prev)) < 1e-12


def test_sin_cos_turn_is_within_one_ulp_and_normals_match_libm_after_the_cast():
    u = noise.uniforms(3, 4, 1_000_000)
    x = 2.0 * np.pi * u
    sin, cos = noise.sin_cos_turn(x)
    ulps = lambda a, b: np.abs(a.view(np.int64) - b.view(np.int64))  # noqa: E731
    assert ulps(sin, np.sin(x)).max() <= 1
    assert ulps(cos, np.cos(x)).max() <= 1
    v = noise.uniforms(5, 6, 1_000_000)
    assert ulps(noise.ln_unit(v), np.log(v)).max() <= 1
    assert noise.ln_unit(np.array([1.0]))[0] == 0.0
    pairs = noise.uniforms(11, 2, 2_000_000).reshape(-1, 2)
    r = np.sqrt(-2.0 * np.log(pairs[:, 0]))
    angle = 2.0 * np.pi * pairs[:, 1]
    libm = np.stack([r * np.cos(angle), r * np.sin(angle)], axis=1).reshape(-1).astype(np.float32)
    assert np.array_equal(noise.normals(11, 2, 2_000_000), libm)

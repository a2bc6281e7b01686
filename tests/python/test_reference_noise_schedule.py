"""The Python reference's noise and schedule against published values and the SPEC formulas."""

import math
import sys

import numpy as np

from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
from sinmdm_reference import noise, schedule  # noqa: E402


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

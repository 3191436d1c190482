"""Counter-based random numbers: deterministic per key, independent of the batch, statistically sound."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.sim.rng import STREAM_SENSOR_DETECT, STREAM_V2X_LOSS, normals, uniforms


@settings(deadline=None)
@given(st.integers(0, 2**40), st.integers(0, 10**7), st.integers(0, 63))
def test_a_draw_depends_only_on_its_key(seed, step, slot):
    alone = uniforms(np.array([seed]), step, STREAM_V2X_LOSS, slot + 1)[0, slot]
    batch = uniforms(np.array([7, seed, 123456789]), step, STREAM_V2X_LOSS, slot + 1)[1, slot]
    assert alone == batch
    assert 0.0 <= alone < 1.0


def test_streams_steps_and_seeds_differ():
    a = uniforms(np.arange(4), 10, STREAM_V2X_LOSS, 8)
    assert not np.array_equal(a, uniforms(np.arange(4), 10, STREAM_SENSOR_DETECT, 8))
    assert not np.array_equal(a, uniforms(np.arange(4), 11, STREAM_V2X_LOSS, 8))
    assert len(np.unique(a)) == a.size


def test_uniform_and_normal_statistics():
    """200,000 draws: mean, variance and a Kolmogorov–Smirnov distance against the exact distributions."""
    seeds = np.arange(2000)
    u = np.concatenate([uniforms(seeds, step, STREAM_V2X_LOSS, 1)[:, 0] for step in range(100)])
    assert abs(u.mean() - 0.5) < 0.003
    assert abs(u.var() - 1 / 12) < 0.002
    ks_u = np.max(np.abs(np.sort(u) - (np.arange(u.size) + 0.5) / u.size))
    assert ks_u < 1.63 / math.sqrt(u.size)  # 1 % critical value
    z = normals(seeds, 3, STREAM_V2X_LOSS, 100).ravel()
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1.0) < 0.01
    cdf = 0.5 * (1.0 + np.vectorize(math.erf)(np.sort(z) / math.sqrt(2.0)))
    assert np.max(np.abs(cdf - (np.arange(z.size) + 0.5) / z.size)) < 1.63 / math.sqrt(z.size)
    # neighbouring steps of one seed are uncorrelated
    series = np.array([uniforms(np.array([42]), step, STREAM_V2X_LOSS, 1)[0, 0] for step in range(20000)])
    assert abs(np.corrcoef(series[:-1], series[1:])[0, 1]) < 0.03

"""Truncated normal draws of a sweep design: rejection as before, the inverse CDF where rejection gives up."""

from __future__ import annotations

import time
import zlib

import numpy as np
import pytest

from vrusim.sweep import design as design_module
from vrusim.sweep.spec import Parameter, parse_parameter


def generator(path: str) -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([3, zlib.crc32(path.encode())])))


def rejection_as_before(rng: np.random.Generator, p: Parameter, count: int) -> np.ndarray:
    """The sampler of earlier versions (which gave up after 100,000 rounds)."""
    out, missing = np.empty(count), np.arange(count)
    for _ in range(100_000):
        draws = rng.normal(p.mean, p.std, missing.size)
        keep = (draws >= p.low) & (draws <= p.high)
        out[missing[keep]] = draws[keep]
        missing = missing[~keep]
        if missing.size == 0:
            return out
    raise AssertionError("gave up")


@pytest.mark.parametrize(
    "args", [[1.5, 0.4, 0.8, 2.5], [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, -4.0, -3.0], [10.0, 2.0, 10.0, 10.5]]
)
def test_windows_rejection_handles_draw_what_they_drew_before(args):
    p = parse_parameter("x", {"truncated_normal": args})
    drawn = design_module._draw(p, 3, 5000)
    assert np.array_equal(drawn, rejection_as_before(generator("x"), p, 5000))


def test_a_window_rejection_cannot_fill_is_drawn_exactly_and_fast():
    p = parse_parameter("vrus[0].trigger.at_time_s", {"truncated_normal": [0, 1, 4.5, 5.5]})  # mass 3.4e-6
    started = time.perf_counter()
    drawn = design_module._draw(p, 3, 20_000)
    assert time.perf_counter() - started < 1.0
    assert drawn.min() >= 4.5 and drawn.max() <= 5.5
    # N(0, 1) on [4.5, 5.5]: mean (φ(4.5) − φ(5.5)) / mass ≈ 4.7035, about 0.19 std
    assert abs(drawn.mean() - 4.7035) < 0.01


def test_a_window_below_the_mean_is_drawn_exactly_too():
    p = parse_parameter("x", {"truncated_normal": [0, 1, -5.5, -4.5]})
    drawn = design_module._draw(p, 3, 20_000)
    assert drawn.min() >= -5.5 and drawn.max() <= -4.5 and abs(drawn.mean() + 4.7035) < 0.01


def test_when_rejection_gives_up_the_inverse_cdf_draws_the_values(monkeypatch):
    from vrusim.sweep import truncated

    monkeypatch.setattr(truncated, "MAX_REJECTION_ROUNDS", 2)
    p = parse_parameter("x", {"truncated_normal": [0, 1, 2.0, 2.5]})  # mass 0.017: rejection needs ~500 rounds
    drawn = design_module._draw(p, 3, 1000)
    assert drawn.min() >= 2.0 and drawn.max() <= 2.5

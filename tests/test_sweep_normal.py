"""Φ and Φ⁻¹ of the sweep's Gaussian copula equal SciPy's `ndtr` / `ndtri` bit for bit, so dropping SciPy from
the core install changed no correlated design."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ndtr, ndtri

import vrusim.sweep.design as design_module
from test_sweep_spec import CORRELATED, spec
from vrusim.sweep.design import make_design
from vrusim.sweep.normal import normal_cdf, normal_quantile
from vrusim.sweep.plan import make_plan

RNG = np.random.default_rng(20240615)


def assert_same_bits(ours: np.ndarray, reference: np.ndarray) -> None:
    """Equal as IEEE-754 bit patterns (NaN equal to NaN, whatever its payload; -0.0 differs from 0.0)."""
    ours, reference = np.asarray(ours, dtype=float), np.asarray(reference, dtype=float)
    assert ours.shape == reference.shape
    both_nan = np.isnan(ours) & np.isnan(reference)
    differ = (ours.view(np.int64) != reference.view(np.int64)) & ~both_nan
    assert not differ.any(), list(zip(ours[differ][:5], reference[differ][:5], strict=True))


CDF_POINTS = np.concatenate(
    [
        RNG.standard_normal(200_000),  # the copula's inputs
        RNG.uniform(-1.5, 1.5, 100_000),  # |x|/√2 < 1: the erf branch, both signs
        RNG.uniform(1.4, 11.4, 100_000) * RNG.choice([-1.0, 1.0], 100_000),  # erfc, 1 <= |x|/√2 < 8
        RNG.uniform(11.3, 40.0, 50_000) * RNG.choice([-1.0, 1.0], 50_000),  # erfc's far branch and underflow
        np.nextafter(np.sqrt(2.0), [0.0, 3.0]),  # around the branch points
        [np.sqrt(2.0), -np.sqrt(2.0), 8 * np.sqrt(2.0), -8 * np.sqrt(2.0), 37.519379347, -38.5, 38.5],
        [0.0, -0.0, 5e-324, -5e-324, 1e-300, np.inf, -np.inf, np.nan],
    ]
)
QUANTILE_POINTS = np.concatenate(
    [
        RNG.uniform(0.0, 1.0, 200_000),
        10.0 ** RNG.uniform(-14.0, -0.8, 100_000),  # lower tail, sqrt(-2 log p) in [2, 8)
        10.0 ** RNG.uniform(-323.0, -13.8, 50_000),  # far tail, [8, 64), subnormals included
        1.0 - 10.0 ** RNG.uniform(-16.0, -0.8, 100_000),  # upper tail, mirrored
        np.nextafter(np.exp(-2.0), [0.0, 1.0]),
        np.nextafter(1.0 - np.exp(-2.0), [0.0, 1.0]),
        [np.exp(-2.0), 1.0 - np.exp(-2.0), np.exp(-32.0), 0.5, np.nextafter(1.0, 0.0), 5e-324],
        [0.0, 1.0, -0.0, -1e-300, 1.0 + 1e-15, -np.inf, np.inf, np.nan],
    ]
)


def test_normal_cdf_equals_scipy_ndtr_bit_for_bit():
    assert_same_bits(normal_cdf(CDF_POINTS), ndtr(CDF_POINTS))


def test_normal_quantile_equals_scipy_ndtri_bit_for_bit():
    assert_same_bits(normal_quantile(QUANTILE_POINTS), ndtri(QUANTILE_POINTS))


@pytest.mark.parametrize("value", [-3.0, -0.2, 0.0, 1.7, 9.0])
def test_scalars_give_numpy_scalars(value):
    assert isinstance(normal_cdf(value), np.float64)
    assert normal_cdf(value) == ndtr(value)
    p = float(ndtr(value))
    assert isinstance(normal_quantile(p), np.float64)
    assert normal_quantile(p) == ndtri(p)


def test_shapes_are_kept():
    grid = RNG.standard_normal((3, 4))
    assert normal_cdf(grid).shape == (3, 4)
    assert normal_quantile(normal_cdf(grid)).shape == (3, 4)
    assert normal_cdf(np.empty(0)).shape == (0,)


def test_a_wrong_coefficient_would_be_seen():
    """The bit comparison can fail: one coefficient off by one unit in the last place changes some values."""
    import vrusim.sweep.normal as normal

    original = normal._CENTRE_P
    try:
        normal._CENTRE_P = (np.nextafter(original[0], 0.0), *original[1:])
        changed = normal_quantile(QUANTILE_POINTS) != ndtri(QUANTILE_POINTS)
    finally:
        normal._CENTRE_P = original
    assert changed.any()


def test_correlated_designs_are_the_ones_scipy_drew(monkeypatch):
    """Every column of correlated designs equals the design drawn through SciPy (the code before it went)."""
    correlation = [
        {"between": ["ego.cruise_speed_mps", "vrus[0].top_speed_mps"], "rho": 0.6},
        {"between": ["vrus[0].trigger.at_time_s", "ego.cruise_speed_mps"], "rho": -0.4},
        {"between": ["v2x.channel", "vrus[0].trigger.at_time_s"], "rho": 0.5},
    ]
    for seed in (0, 7, 123456789):
        plan = make_plan(spec(CORRELATED, samples=20_000, correlation=correlation, seed=seed))
        ours = make_design(plan)
        with monkeypatch.context() as patch:
            patch.setattr(design_module, "normal_cdf", ndtr)
            patch.setattr(design_module, "normal_quantile", ndtri)
            theirs = make_design(plan)
        assert ours.keys() == theirs.keys()
        for name in ours:
            if ours[name].dtype.kind == "f":
                assert_same_bits(ours[name], theirs[name])
            else:
                np.testing.assert_array_equal(ours[name], theirs[name])

"""The ego's heading rotation (`vrusim.sim.ego.rotate`): its shortcuts give the very bits of the full computation,
so the step's speed-up changes no result. A result that is already a unit vector is not renormalised, and an
angle of ±0 skips the Taylor series."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from vrusim.sim.ego import rotate, rotated


def renormalised(hx: float, hy: float, angle: float) -> tuple[float, float]:
    """The rotation as computed before the shortcut: the same rotation, always renormalised, operation for
    operation (IEEE doubles, as numba's)."""
    rx, ry = rotated(hx, hy, angle)
    inv = 1.0 / math.sqrt(rx * rx + ry * ry)
    return rx * inv, ry * inv


def series(hx: float, hy: float, angle: float) -> tuple[float, float]:
    """`rotated` for a small angle as written before its ±0 shortcut: the 5th-order Taylor sine and cosine,
    operation for operation."""
    a2 = angle * angle
    c = 1.0 - a2 * (0.5 - a2 * (1.0 / 24.0))
    s = angle * (1.0 - a2 * ((1.0 / 6.0) - a2 * (1.0 / 120.0)))
    return c * hx - s * hy, s * hx + c * hy


def bits(pair: tuple[float, float]) -> bytes:
    return np.array(pair, dtype=np.float64).tobytes()


AXES = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (-0.0, 1.0), (1.0, -0.0)]
"""Headings along an axis, signed zeros included: the shortcut's case on a straight route."""
headings = st.one_of(
    st.sampled_from(AXES),
    st.floats(-math.pi, math.pi).map(lambda a: (math.cos(a), math.sin(a))),
    st.floats(-math.pi, math.pi).map(lambda a: renormalised(math.cos(a), math.sin(a), 0.0)),
)
angles = st.one_of(st.sampled_from([0.0, -0.0]), st.floats(-0.05, 0.05), st.floats(-3.0, 3.0))


@given(headings, angles)
def test_rotation_equals_full_renormalisation_bit_for_bit(heading, angle):
    assert bits(rotate(*heading, angle)) == bits(renormalised(*heading, angle))


def test_shortcut_is_taken_along_an_axis_and_keeps_signed_zeros():
    assert bits(rotate(1.0, 0.0, 0.0)) == bits((1.0, 0.0))
    assert bits(rotate(-0.0, 1.0, 0.0)) == bits(renormalised(-0.0, 1.0, 0.0))


def test_a_vector_off_the_unit_circle_is_renormalised():
    hx, hy = rotate(3.0, 4.0, 0.0)
    assert math.isclose(math.hypot(hx, hy), 1.0, rel_tol=0, abs_tol=1e-15)
    assert bits((hx, hy)) == bits(renormalised(3.0, 4.0, 0.0))


components = st.one_of(st.sampled_from([0.0, -0.0, 1.0, -1.0]), st.floats(allow_nan=False))


@given(components, components, st.sampled_from([0.0, -0.0]))
def test_a_zero_angle_gives_the_series_bits_signed_zeros_included(hx, hy, angle):
    assert bits(rotated(hx, hy, angle)) == bits(series(hx, hy, angle))

"""Evaluate an OpenDRIVE road's reference line: station s (m) -> world x, y (m) and heading (rad).

Every plan-view geometry kind of ASAM OpenDRIVE 1.6 / 1.8 (chapter "Geometry"): line, arc and paramPoly3 in
closed form; spiral (clothoid) by the Gauss-Legendre quadrature of `geometry.paths` (round-off accuracy);
poly3 with s as the true arc length of v(u), inverted by tabulated quadrature and Newton steps (< 1e-12 m).
paramPoly3 maps s to p linearly, as the standard defines (p = ds, or ds / length when normalized): its arc
length is not re-parametrised. Formulas and sources: docs/opendrive_import.md.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.errors import UserInputError
from vrusim.formats.xodr_model import Arc, Geometry, ParamPoly3, Poly3, Road, Spiral, Straight
from vrusim.geometry.paths import Clothoid, PathSpec, path_poses

Poses = tuple[np.ndarray, np.ndarray, np.ndarray]
"""x (m), y (m), heading (rad, not wrapped) at each station."""

STATION_TOLERANCE_M = 1e-6
"""A station this far outside [0, road length] is clamped onto the road; further is an error."""

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)
_POLY3_STEP_M = 0.25
"""Sub-interval of u over which poly3 arc length is tabulated (8-point Gauss-Legendre per sub-interval)."""
_NEWTON_STEPS = 6


def _to_world(geometry: Geometry, u: np.ndarray, v: np.ndarray, local_heading: np.ndarray) -> Poses:
    """Local (u along the start heading, v to its left) -> world."""
    cos_h, sin_h = math.cos(geometry.hdg_rad), math.sin(geometry.hdg_rad)
    return (
        geometry.x_m + u * cos_h - v * sin_h,
        geometry.y_m + u * sin_h + v * cos_h,
        geometry.hdg_rad + local_heading,
    )


def _arc(geometry: Geometry, curvature: float, ds: np.ndarray) -> Poses:
    """Chord of length ds sin(k ds / 2) / (k ds / 2) at half the turn: exact, and a line as k -> 0."""
    turn = curvature * ds
    chord = ds * np.sinc(turn / (2 * np.pi))  # np.sinc(x) = sin(pi x) / (pi x)
    return _to_world(geometry, chord * np.cos(turn / 2), chord * np.sin(turn / 2), turn)


def _spiral(geometry: Geometry, shape: Spiral, ds: np.ndarray) -> Poses:
    if geometry.length_m == 0.0:
        return _to_world(geometry, np.zeros_like(ds), np.zeros_like(ds), np.zeros_like(ds))
    piece = Clothoid(shape.curv_start_per_m, shape.curv_end_per_m, geometry.length_m)
    x, y, heading, _ = path_poses(PathSpec(geometry.x_m, geometry.y_m, geometry.hdg_rad, (piece,)), ds)
    return x, y, heading


def _polyval(coefficients: tuple[float, ...], p: np.ndarray) -> np.ndarray:
    a, b, c, d = coefficients
    return a + p * (b + p * (c + p * d))


def _slope(coefficients: tuple[float, ...], p: np.ndarray) -> np.ndarray:
    _, b, c, d = coefficients
    return b + p * (2 * c + p * 3 * d)


def _poly3_u(shape: Poly3, length_m: float, ds: np.ndarray) -> np.ndarray:
    """u at arc length ds along v(u): cumulative quadrature over u in [0, length] (arc >= u), then Newton."""
    coefficients = (shape.a, shape.b, shape.c, shape.d)

    def speed(u: np.ndarray) -> np.ndarray:
        return np.sqrt(1.0 + _slope(coefficients, u) ** 2)

    def arc(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        half = 0.5 * (hi - lo)
        nodes = (lo + hi)[..., None] * 0.5 + half[..., None] * _GAUSS_NODES
        return half * (speed(nodes) * _GAUSS_WEIGHTS).sum(axis=-1)

    count = max(1, math.ceil(length_m / _POLY3_STEP_M))
    knots = np.linspace(0.0, length_m, count + 1)
    cumulative = np.concatenate([[0.0], np.cumsum(arc(knots[:-1], knots[1:]))])
    index = np.clip(np.searchsorted(cumulative, ds, side="right") - 1, 0, count - 1)
    u = knots[index] + (ds - cumulative[index]) / speed(knots[index])
    for _ in range(_NEWTON_STEPS):
        u = u - (cumulative[index] + arc(knots[index], u) - ds) / speed(u)
    return u


def geometry_poses(geometry: Geometry, ds_m: np.ndarray) -> Poses:
    """Pose at distances `ds_m` (m, >= 0) from the start of one geometry (past its end: extrapolated)."""
    ds = np.asarray(ds_m, dtype=float)
    shape = geometry.shape
    if isinstance(shape, Straight):
        return _arc(geometry, 0.0, ds)
    if isinstance(shape, Arc):
        return _arc(geometry, shape.curvature_per_m, ds)
    if isinstance(shape, Spiral):
        return _spiral(geometry, shape, ds)
    if isinstance(shape, Poly3):
        u = _poly3_u(shape, geometry.length_m, ds)
        coefficients = (shape.a, shape.b, shape.c, shape.d)
        return _to_world(geometry, u, _polyval(coefficients, u), np.arctan(_slope(coefficients, u)))
    if isinstance(shape, ParamPoly3):
        p = ds / geometry.length_m if shape.normalized and geometry.length_m > 0 else ds
        heading = np.arctan2(_slope(shape.v, p), _slope(shape.u, p))
        return _to_world(geometry, _polyval(shape.u, p), _polyval(shape.v, p), heading)
    raise TypeError(f"unknown geometry shape {shape!r}")


def checked_stations(road: Road, s_m: np.ndarray | float) -> np.ndarray:
    """Stations as a float array clamped onto [0, length]; one further out is a UserInputError naming the road."""
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    outside = (s < -STATION_TOLERANCE_M) | (s > road.length_m + STATION_TOLERANCE_M) | ~np.isfinite(s)
    if outside.any():
        raise UserInputError(
            f"road {road.id!r}: station s = {s[outside][0]:g} m is outside the road (0 to {road.length_m:g} m)"
        )
    return np.clip(s, 0.0, road.length_m)


def reference_poses(road: Road, s_m: np.ndarray | float) -> Poses:
    """Pose of the reference line of `road` at stations `s_m` (m): each from the last geometry starting at or
    before it."""
    s = checked_stations(road, s_m)
    starts = np.array([geometry.s_m for geometry in road.geometries])
    index = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)
    out = np.empty((3, s.size))
    for number in np.unique(index):
        mask = index == number
        geometry = road.geometries[number]
        out[:, mask] = geometry_poses(geometry, np.maximum(s[mask] - geometry.s_m, 0.0))
    return out[0], out[1], out[2]

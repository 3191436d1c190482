"""Prescribed paths: lines, arcs, clothoids and polylines, and their sampling at a fixed arc-length spacing.

Every path (ego route or VRU path) is sampled at a fixed arc-length spacing `SAMPLE_SPACING_M`. Identical paths
share one table row, so a sweep over speeds stores one route. Between samples a path is linear; beyond either
end it continues along its first / last segment (a VRU keeps walking straight past its last waypoint).
Lines and arcs are sampled exactly (chord error of a 0.2 m spacing on a 10 m radius: 0.5 mm), clothoids by
Gauss-Legendre quadrature of their heading (error at round-off level).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SAMPLE_SPACING_M = 0.2
"""Arc-length spacing of path samples, m."""


@dataclass(frozen=True)
class Line:
    """A straight piece of `length_m`."""

    length_m: float


@dataclass(frozen=True)
class Arc:
    """A circular arc of `radius_m`, turning by `angle_rad` (positive: left, counter-clockwise)."""

    radius_m: float
    angle_rad: float

    @property
    def length_m(self) -> float:
        return self.radius_m * abs(self.angle_rad)


@dataclass(frozen=True)
class Clothoid:
    """A clothoid (Euler spiral) of `length_m`: curvature linear in arc length from start to end (1/m, signed).

    Positive curvature turns left. Its heading changes by `length_m * (start + end) / 2`.
    """

    start_curvature_per_m: float
    end_curvature_per_m: float
    length_m: float

    @property
    def sharpness_per_m2(self) -> float:
        """Curvature change per metre, 1/m^2."""
        return (self.end_curvature_per_m - self.start_curvature_per_m) / self.length_m

    @property
    def angle_rad(self) -> float:
        """Heading change over the piece, rad (positive: left)."""
        return self.length_m * (self.start_curvature_per_m + self.end_curvature_per_m) / 2


Piece = Line | Arc | Clothoid


@dataclass(frozen=True)
class PathSpec:
    """A start pose (m, rad) and a chain of pieces; hashable, so identical paths are stored once."""

    x0_m: float
    y0_m: float
    heading0_rad: float
    pieces: tuple[Piece, ...]

    @property
    def length_m(self) -> float:
        return sum(piece.length_m for piece in self.pieces)


@dataclass(frozen=True)
class PolylineSpec:
    """A polyline through points (m); sampled along its segments."""

    points: tuple[tuple[float, float], ...]

    @property
    def length_m(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.points, self.points[1:], strict=False))


_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)
_QUADRATURE_STEP_M = 0.25
"""Longest sub-interval of the clothoid quadrature (8-point Gauss-Legendre: round-off accuracy)."""


def _clothoid_heading(piece: Clothoid, heading: float, local: np.ndarray) -> np.ndarray:
    return heading + local * (piece.start_curvature_per_m + 0.5 * piece.sharpness_per_m2 * local)


def _clothoid_offsets(piece: Clothoid, heading: float, local: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Displacement (x, y) from the piece start at stations `local` in [0, length_m], by cumulative quadrature."""
    knots, inverse = np.unique(np.concatenate([[0.0], local]), return_inverse=True)
    parts = np.maximum(np.ceil(np.diff(knots) / _QUADRATURE_STEP_M), 1).astype(np.int64)
    owner = np.repeat(np.arange(len(parts)), parts)  # interval of each sub-interval
    first = np.cumsum(parts) - parts
    width = (np.diff(knots) / parts)[owner]
    lo = knots[owner] + (np.arange(len(owner)) - first[owner]) * width
    nodes = lo[:, None] + 0.5 * width[:, None] * (_GAUSS_NODES + 1.0)
    angles = _clothoid_heading(piece, heading, nodes)
    weights = 0.5 * width[:, None] * _GAUSS_WEIGHTS
    sub_x, sub_y = (np.cos(angles) * weights).sum(axis=1), (np.sin(angles) * weights).sum(axis=1)
    cum_x = np.concatenate([[0.0], np.cumsum(np.bincount(owner, sub_x, len(parts)))])
    cum_y = np.concatenate([[0.0], np.cumsum(np.bincount(owner, sub_y, len(parts)))])
    return cum_x[inverse[1:]], cum_y[inverse[1:]]


def _piece_poses(piece: Piece, x: float, y: float, heading: float, local: np.ndarray) -> tuple[np.ndarray, ...]:
    """(x, y, heading, curvature) at stations `local` >= 0 from the piece start; straight on past its end."""
    if isinstance(piece, Line):
        return (
            x + local * math.cos(heading),
            y + local * math.sin(heading),
            np.full(local.shape, heading),
            np.zeros(local.shape),
        )
    if isinstance(piece, Arc):
        sign = 1.0 if piece.angle_rad > 0 else -1.0
        centre_x = x - sign * piece.radius_m * math.sin(heading)
        centre_y = y + sign * piece.radius_m * math.cos(heading)
        angles = heading + sign * np.minimum(local, piece.length_m) / piece.radius_m
        beyond = np.maximum(local - piece.length_m, 0.0)
        px = centre_x + sign * piece.radius_m * np.sin(angles) + beyond * np.cos(angles)
        py = centre_y - sign * piece.radius_m * np.cos(angles) + beyond * np.sin(angles)
        curvature = np.where(local <= piece.length_m, sign / piece.radius_m, 0.0)
        return px, py, angles, curvature
    within = np.minimum(local, piece.length_m)
    angles = _clothoid_heading(piece, heading, within)
    dx, dy = _clothoid_offsets(piece, heading, within)
    beyond = np.maximum(local - piece.length_m, 0.0)
    curvature = np.where(local <= piece.length_m, piece.start_curvature_per_m + piece.sharpness_per_m2 * local, 0.0)
    return x + dx + beyond * np.cos(angles), y + dy + beyond * np.sin(angles), angles, curvature


def _piece_end(piece: Piece, x: float, y: float, heading: float) -> tuple[float, float, float]:
    """The pose (x, y, heading) at the end of a piece that starts at (x, y, heading)."""
    if isinstance(piece, Line):
        return x + piece.length_m * math.cos(heading), y + piece.length_m * math.sin(heading), heading
    if isinstance(piece, Arc):
        sign = 1.0 if piece.angle_rad > 0 else -1.0
        centre_x = x - sign * piece.radius_m * math.sin(heading)
        centre_y = y + sign * piece.radius_m * math.cos(heading)
        heading += piece.angle_rad
        return (
            centre_x + sign * piece.radius_m * math.sin(heading),
            centre_y - sign * piece.radius_m * math.cos(heading),
            heading,
        )
    end_x, end_y, _, _ = _piece_poses(piece, x, y, heading, np.array([piece.length_m]))
    return float(end_x[0]), float(end_y[0]), heading + piece.angle_rad


def path_poses(spec: PathSpec, station_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Exact pose of a path at stations (m, >= 0): x (m), y (m), heading (rad, unwrapped), curvature (1/m).

    Past the end the path continues straight along its last heading (curvature 0).
    """
    stations = np.atleast_1d(np.asarray(station_m, dtype=float))
    if np.any(stations < 0.0):
        raise ValueError("stations must be >= 0")
    out = np.empty((4, stations.size))
    x, y, heading, start = spec.x0_m, spec.y0_m, spec.heading0_rad, 0.0
    pieces = list(spec.pieces) or [Line(0.0)]
    for index, piece in enumerate(pieces):
        last = index == len(pieces) - 1
        end = start + piece.length_m
        mask = (stations >= start) & ((stations < end) | last)
        if mask.any():
            out[:, mask] = _piece_poses(piece, x, y, heading, stations[mask] - start)
        x, y, heading = _piece_end(piece, x, y, heading)
        start = end
    return out[0], out[1], out[2], out[3]


def sample_path(spec: PathSpec, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """Sample a path every `spacing_m`: array [N, 5] of x, y, tangent x, tangent y, curvature (1/m)."""
    count = max(2, math.ceil(spec.length_m / spacing_m - 1e-9) + 1)
    stations = np.arange(count) * spacing_m
    out = np.empty((count, 5))
    x, y, heading, start = spec.x0_m, spec.y0_m, spec.heading0_rad, 0.0
    pieces = list(spec.pieces) or [Line(spacing_m)]
    for index, piece in enumerate(pieces):
        last = index == len(pieces) - 1
        end = start + piece.length_m
        mask = (stations >= start) & ((stations < end) | last)
        if mask.any():
            px, py, angles, curvature = _piece_poses(piece, x, y, heading, stations[mask] - start)
            out[mask] = np.column_stack([px, py, np.cos(angles), np.sin(angles), curvature])
        x, y, heading = _piece_end(piece, x, y, heading)
        start = end
    return out


def sample_polyline(spec: PolylineSpec, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """Sample a polyline every `spacing_m` (corners are cut by at most one spacing)."""
    points = np.asarray(spec.points, dtype=float)
    seg = np.diff(points, axis=0)
    seg_len = np.hypot(seg[:, 0], seg[:, 1])
    cumulative = np.concatenate([[0.0], np.cumsum(seg_len)])
    count = max(2, math.ceil(cumulative[-1] / spacing_m - 1e-9) + 1)
    stations = np.arange(count) * spacing_m
    index = np.clip(np.searchsorted(cumulative, stations, side="right") - 1, 0, len(seg) - 1)
    local = stations - cumulative[index]
    tangent = seg[index] / seg_len[index, None]
    xy = points[index] + tangent * local[:, None]
    return np.column_stack([xy, tangent, np.zeros(count)])

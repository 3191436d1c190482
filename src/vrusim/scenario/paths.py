"""Prescribed paths as densely sampled tables, evaluated and projected onto for whole batches at once.

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
from numba import njit

from vrusim.scenario.schema import Ego, Route, Vru

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


def turn_pieces(route: Route) -> tuple[Piece, ...]:
    """The turning part of a left / right route: an arc, or clothoid + arc + clothoid when `clothoid_angle_deg` > 0."""
    sign = 1.0 if route.kind == "left" else -1.0
    arc = Arc(route.radius_m, sign * math.radians(route.angle_deg))
    if route.clothoid_angle_deg == 0.0:
        return (arc,)
    entry, arc_curvature = sign / route.clothoid_entry_radius_m, sign / route.radius_m
    length = 2 * math.radians(route.clothoid_angle_deg) / (1 / route.clothoid_entry_radius_m + 1 / route.radius_m)
    return Clothoid(entry, arc_curvature, length), arc, Clothoid(arc_curvature, entry, length)


def route_spec(route: Route, x0_m: float, y0_m: float, heading0_rad: float) -> PathSpec:
    """A route as a path from the start pose of the rear axle (m, m, rad)."""
    if route.kind == "straight":
        return PathSpec(x0_m, y0_m, heading0_rad, (Line(route.length_m),))
    turn = turn_pieces(route)
    exit_length = route.length_m - route.turn_at_m - sum(piece.length_m for piece in turn)
    pieces = tuple(p for p in (Line(route.turn_at_m), *turn, Line(exit_length)) if p.length_m > 0)
    return PathSpec(x0_m, y0_m, heading0_rad, pieces)


def ego_route_spec(ego: Ego) -> PathSpec:
    """The route of the ego's rear-axle centre, which starts behind the rectangle centre given in `ego.start`.

    A reversing ego is packed as a vehicle mirrored front to back (see `Ego.travel_heading_deg`): its
    simulated rear axle is the real front axle.
    """
    heading = math.radians(ego.travel_heading_deg)
    back = ego.length_m / 2 - ego.trailing_overhang_m
    x0 = ego.start.x_m - back * math.cos(heading)
    y0 = ego.start.y_m - back * math.sin(heading)
    return route_spec(ego.route, x0, y0, heading)


def vru_path_spec(vru: Vru) -> PathSpec | PolylineSpec:
    """A VRU's path: a straight line along `heading_deg`, or the polyline through its waypoints."""
    if vru.heading_deg is not None:
        return PathSpec(vru.start.x_m, vru.start.y_m, math.radians(vru.heading_deg), (Line(SAMPLE_SPACING_M),))
    points = [(vru.start.x_m, vru.start.y_m)] + [(p.x_m, p.y_m) for p in vru.path or []]
    return PolylineSpec(tuple(points))


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


class PathTable:
    """Sampled paths stacked into arrays [rows, N]; evaluate and project for a batch of (row, station) pairs."""

    def __init__(self, specs: list[PathSpec | PolylineSpec], spacing_m: float = SAMPLE_SPACING_M):
        self.spacing_m = spacing_m
        samples = [
            sample_path(s, spacing_m) if isinstance(s, PathSpec) else sample_polyline(s, spacing_m) for s in specs
        ]
        self.lengths_m = np.array([s.length_m for s in specs])
        width = max(len(s) for s in samples)
        table = np.empty((len(samples), width, 5))
        for row, sample in enumerate(samples):
            table[row, : len(sample)] = sample
            if len(sample) < width:  # pad by continuing straight along the last segment
                extra = np.arange(1, width - len(sample) + 1) * spacing_m
                last = sample[-1]
                direction = (sample[-1, :2] - sample[-2, :2]) / spacing_m
                table[row, len(sample) :, 0] = last[0] + extra * direction[0]
                table[row, len(sample) :, 1] = last[1] + extra * direction[1]
                table[row, len(sample) :, 2:4] = direction
                table[row, len(sample) :, 4] = 0.0
        self.width = width
        counts = np.array([len(sample) for sample in samples], dtype=np.int64)
        # index of each row's last sample, at every flat index of the row: kernels read it at a row's offset
        # without dividing the offset by the width
        self._last = np.repeat(counts - 1, width)
        self._x = np.ascontiguousarray(table[:, :, 0]).ravel()
        self._y = np.ascontiguousarray(table[:, :, 1]).ravel()
        self._kappa = np.ascontiguousarray(table[:, :, 4]).ravel()
        # unit direction of each segment (sample j -> j + 1), precomputed so evaluation needs no square root
        seg = np.diff(table[:, :, :2], axis=1, append=table[:, -1:, :2] + table[:, -1:, 2:4] * spacing_m)
        seg /= np.linalg.norm(seg, axis=2, keepdims=True)
        self._tangent = np.ascontiguousarray(seg.reshape(-1, 2))
        self.samples = table

    @property
    def arrays(self) -> tuple:
        """(x, y, segment unit tangents, curvature, last sample index, 1 / spacing, width) for compiled kernels.

        Every array but the tangents [rows x width, 2] is flat [rows x width]: entry `offset + j` is sample j of
        the row starting at `offset`; the last sample index is the row's, repeated along it.

        Beyond a path's last sample, evaluation extends its own last segment (never the padding), so a path
        gives bit-identical results whatever else shares the table.
        """
        return self._x, self._y, self._tangent, self._kappa, self._last, 1.0 / self.spacing_m, self.width

    def locate(self, row_offset: np.ndarray, station_m: np.ndarray):
        """Return (x, y, unit tangent x, unit tangent y, curvature) at `station_m` of each path.

        `row_offset` is `row * width` (same shape as `station_m`).
        """
        shape = np.shape(station_m)
        out = _locate_many(self.arrays, np.ravel(row_offset), np.ravel(station_m).astype(float))
        return tuple(a.reshape(shape) for a in out)


@njit(cache=True, inline="always")
def locate_point(path, offset, station):  # pragma: no cover
    """(x, y, unit tangent x, unit tangent y, curvature) of one path at one station (compiled).

    `path` is `PathTable.arrays`; `offset` is the path's row times the table width.
    """
    xs, ys, tangents, kappas, last, inv_spacing, _ = path
    scaled = station * inv_spacing
    j = min(max(math.floor(scaled), 0), last[offset] - 1)
    flat = offset + j
    frac = scaled - j
    x0, y0 = xs[flat], ys[flat]
    return (
        x0 + frac * (xs[flat + 1] - x0),
        y0 + frac * (ys[flat + 1] - y0),
        tangents[flat, 0],
        tangents[flat, 1],
        kappas[flat],
    )


@njit(cache=True, inline="always")
def project_point(path, offset, station, px, py, iterations):  # pragma: no cover (compiled)
    """Newton refinement of the foot point of (px, py): (station, x, y, tangent x, tangent y, curvature)."""
    for _ in range(iterations):
        x, y, tx, ty, _k = locate_point(path, offset, station)
        station = max(station + (px - x) * tx + (py - y) * ty, 0.0)
    x, y, tx, ty, k = locate_point(path, offset, station)
    return station, x, y, tx, ty, k


@njit(cache=True)
def _locate_many(path, offsets, stations):  # pragma: no cover
    n = stations.shape[0]
    out = np.empty((5, n))
    for i in range(n):
        x, y, tx, ty, k = locate_point(path, offsets[i], stations[i])
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i] = x, y, tx, ty, k
    return out[0], out[1], out[2], out[3], out[4]


@njit(cache=True, inline="always")
def nearest_station(path, offset, px, py):  # pragma: no cover (compiled)
    """Approximate foot-point station of (px, py) on the path and its straight extension past the end (O(N)).

    Candidates: the nearest of the path's own samples, and the foot point on the extension after its last
    sample; the nearest wins. Nothing moves backwards along a path, so the part before its start is never a
    candidate. Refine with `project_point`.
    """
    xs, ys, tangents, _, lasts, inv_spacing, _ = path
    last = lasts[offset]
    best, best_s = np.inf, 0.0
    for j in range(last + 1):
        dx, dy = xs[offset + j] - px, ys[offset + j] - py
        d = dx * dx + dy * dy
        if d < best:
            best, best_s = d, j / inv_spacing
    tx, ty = tangents[offset + last - 1, 0], tangents[offset + last - 1, 1]
    dx, dy = px - xs[offset + last], py - ys[offset + last]
    along = dx * tx + dy * ty
    across = dx * ty - dy * tx
    if along > 0.0 and across * across < best:
        best_s = last / inv_spacing + along
    return best_s

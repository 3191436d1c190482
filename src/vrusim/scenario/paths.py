"""Prescribed paths as densely sampled tables, evaluated and projected onto for whole batches at once.

Every path (ego route or VRU path) is sampled at a fixed arc-length spacing `SAMPLE_SPACING_M`. Identical paths
share one table row, so a sweep over speeds stores one route. Between samples a path is linear; beyond either
end it continues along its first / last segment (a VRU keeps walking straight past its last waypoint).
Lines and arcs are sampled exactly (chord error of a 0.2 m spacing on a 10 m radius: 0.5 mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from vrusim.scenario.schema import Ego, Vru

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


Piece = Line | Arc


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
        local = stations[mask] - start
        if isinstance(piece, Line):
            out[mask] = np.column_stack(
                [
                    x + local * math.cos(heading),
                    y + local * math.sin(heading),
                    np.full(local.shape, math.cos(heading)),
                    np.full(local.shape, math.sin(heading)),
                    np.zeros(local.shape),
                ]
            )
            x, y = x + piece.length_m * math.cos(heading), y + piece.length_m * math.sin(heading)
        else:
            sign = 1.0 if piece.angle_rad > 0 else -1.0
            centre_x = x - sign * piece.radius_m * math.sin(heading)
            centre_y = y + sign * piece.radius_m * math.cos(heading)
            angles = heading + sign * np.minimum(local, piece.length_m) / piece.radius_m
            beyond = np.maximum(local - piece.length_m, 0.0)
            px = centre_x + sign * piece.radius_m * np.sin(angles) + beyond * np.cos(angles)
            py = centre_y - sign * piece.radius_m * np.cos(angles) + beyond * np.sin(angles)
            curvature = np.where(local <= piece.length_m, sign / piece.radius_m, 0.0)
            out[mask] = np.column_stack([px, py, np.cos(angles), np.sin(angles), curvature])
            heading += piece.angle_rad
            x = centre_x + sign * piece.radius_m * math.sin(heading)
            y = centre_y - sign * piece.radius_m * math.cos(heading)
        start = end
    return out


def ego_route_spec(ego: Ego) -> PathSpec:
    """The route of the ego's rear-axle centre, which starts behind the rectangle centre given in `ego.start`."""
    heading = math.radians(ego.start.heading_deg)
    back = ego.length_m / 2 - ego.rear_overhang_m
    x0 = ego.start.x_m - back * math.cos(heading)
    y0 = ego.start.y_m - back * math.sin(heading)
    route = ego.route
    if route.kind == "straight":
        pieces: tuple[Piece, ...] = (Line(route.length_m),)
    else:
        sign = 1.0 if route.kind == "left" else -1.0
        arc = Arc(route.radius_m, sign * math.radians(route.angle_deg))
        exit_length = route.length_m - route.turn_at_m - arc.length_m
        pieces = tuple(p for p in (Line(route.turn_at_m), arc, Line(exit_length)) if p.length_m > 0)
    return PathSpec(x0, y0, heading, pieces)


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
        self._counts = np.array([len(sample) for sample in samples], dtype=np.int64)
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
        """(x, y, segment unit tangents, curvature, samples per row, 1 / spacing, width) for compiled kernels.

        Beyond a path's last sample, evaluation extends its own last segment (never the padding), so a path
        gives bit-identical results whatever else shares the table.
        """
        return self._x, self._y, self._tangent, self._kappa, self._counts, 1.0 / self.spacing_m, self.width

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
    xs, ys, tangents, kappas, counts, inv_spacing, width = path
    scaled = station * inv_spacing
    j = min(max(math.floor(scaled), 0), counts[offset // width] - 2)
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
    xs, ys, tangents, _, counts, inv_spacing, width = path
    last = counts[offset // width] - 1
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

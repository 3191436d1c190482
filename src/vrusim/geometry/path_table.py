"""Sampled paths in one table, evaluated and projected onto for whole batches at once (compiled).

Identical paths share one table row, so a sweep over speeds stores one route. Between samples a path is linear;
beyond either end it continues along its first / last segment.
"""

from __future__ import annotations

import math

import numpy as np

from vrusim.geometry.paths import SAMPLE_SPACING_M, PathSpec, PolylineSpec, sample_path, sample_polyline
from vrusim.kernels import njit
from vrusim.limits import check_limit


def table_samples(specs: list[PathSpec | PolylineSpec], spacing_m: float) -> tuple[int, float]:
    """(samples of a table of `specs`, the longest path's length in m): rows x the longest row, as sampled."""
    longest_m = max(spec.length_m for spec in specs)
    return len(specs) * max(2, math.ceil(longest_m / spacing_m - 1e-9) + 1), longest_m


def check_table_budget(specs: list[PathSpec | PolylineSpec], spacing_m: float, what: str) -> None:
    """Refuse a table beyond limit `path_samples` before sampling anything."""
    samples, longest_m = table_samples(specs, spacing_m)
    about = f"{len(specs):,} distinct paths x the longest, {longest_m:,.0f} m, sampled every {spacing_m:g} m"
    check_limit("path_samples", samples, f"{what}: {about}")


class PathTable:
    """Sampled paths stacked into arrays [rows, N]; evaluate and project for a batch of (row, station) pairs."""

    def __init__(self, specs: list[PathSpec | PolylineSpec], spacing_m: float = SAMPLE_SPACING_M, what: str = "paths"):
        """Sample `specs` every `spacing_m` (m) into one table; refused (limit `path_samples`, naming `what`) when
        the table, one row of the longest path's samples for each spec, would be too large."""
        check_table_budget(specs, spacing_m, what)
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
        # largest heading change between consecutive segments of each row's own samples, rad
        turn = np.zeros(len(samples))
        for row, count in enumerate(counts):
            a, b = seg[row, : count - 2], seg[row, 1 : count - 1]
            if len(a):
                turn[row] = np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))).max()
        self._max_turn = np.repeat(np.where(np.isfinite(turn), turn, np.pi), width)  # degenerate rows: any turn
        self.samples = table

    @property
    def arrays(self) -> tuple:
        """(x, y, segment unit tangents, curvature, last sample index, 1 / spacing, width, largest turn) for
        compiled kernels.

        Every array but the tangents [rows x width, 2] is flat [rows x width]: entry `offset + j` is sample j of
        the row starting at `offset`; the last sample index and the largest turn (rad: heading change between
        consecutive segments, the bound `planners.route_ttc` skips samples by) are the row's, repeated along it.

        Beyond a path's last sample, evaluation extends its own last segment (never the padding), so a path
        gives bit-identical results whatever else shares the table.
        """
        return (
            self._x, self._y, self._tangent, self._kappa, self._last, 1.0 / self.spacing_m, self.width,
            self._max_turn,
        )  # fmt: skip

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
    xs, ys, tangents, kappas, last, inv_spacing, _, _ = path
    scaled = station * inv_spacing
    top = last[offset] - 1.0
    # the segment index clamped to the row's samples, as a float (exact: whole numbers) so that `frac` does not
    # wait for a conversion back
    j = min(max(np.floor(scaled), 0.0), top)
    # the same index for the loads, from `scaled` clamped first (truncating a number >= 0 floors it), so that
    # the loads do not wait for the rounding; unsigned (>= 0 here), which spares numba's negative-index wrap
    flat = np.uint64(offset) + np.uint64(min(max(scaled, 0.0), top))
    following = flat + np.uint64(1)
    frac = scaled - j
    x0, y0 = xs[flat], ys[flat]
    return (
        x0 + frac * (xs[following] - x0),
        y0 + frac * (ys[following] - y0),
        tangents[flat, 0],
        tangents[flat, 1],
        kappas[flat],
    )


@njit(cache=True, inline="always")
def project_point(path, offset, station, px, py, iterations):  # pragma: no cover (compiled)
    """Newton refinement of the foot point of (px, py): (station, x, y, tangent x, tangent y, curvature)."""
    x, y, tx, ty, k = locate_point(path, offset, station)
    return project_from(path, offset, station, x, y, tx, ty, k, px, py, iterations)


@njit(cache=True, inline="always")
def project_from(path, offset, station, x, y, tx, ty, k, px, py, iterations):  # pragma: no cover (compiled)
    """`project_point` starting at `station`, where the path's point, unit tangent and curvature
    (`locate_point`) are (x, y), (tx, ty) and k already: a projection that starts where another one ended
    reuses its last evaluation (bit-identical to `project_point`).

    A step that leaves a positive station exactly where it is has reached a fixed point: every further step would
    evaluate the same station again and end there, so the loop stops (exact: equal positive floats have the same
    bits; a station of zero is not taken, as 0.0 == -0.0).
    """
    for _ in range(iterations):
        moved = max(station + (px - x) * tx + (py - y) * ty, 0.0)
        if moved == station and moved > 0.0:
            break
        station = moved
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
    xs, ys, tangents, _, lasts, inv_spacing, _, _ = path
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

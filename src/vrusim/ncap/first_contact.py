"""Euro NCAP impact at first contact (FC26 Definitions "Vimpact", §1.2.5): solve and measure it.

FC26 defines the impact as the instant the VUT's profile first touches the target's virtual box, and the impact
location as where the target's reference point is at that instant. In the engine the VUT is an exact
rectangle and the target's contact shape a circle (the approximation of its virtual box, docs/euroncap.md), so
the synchronisation solves for the first rectangle–circle contact with the reference point at the nominal
location. Solvers here work on a VUT route sampled by `vrusim.geometry.paths.sample_path` (rows: rear-axle x,
y, unit tangent x, y, curvature); `reference_point_at_first_contact` measures the result from a traced run.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from vrusim.geometry.contact import rectangle_circle_clearance, to_local_frame
from vrusim.geometry.paths import SAMPLE_SPACING_M

if TYPE_CHECKING:
    from vrusim.engine.simulate import BatchRun

BISECTIONS = 24
"""Bisection steps inside one trace step (measurement)."""
SUBSAMPLES = 400
"""Poses tried inside the bracketing route sample, then interpolated (0.2 m / 400 = 0.5 mm before
interpolation: below the 1 mm goal)."""
SIDE_SEARCH_M = 5.0
"""How far back along its path a side-impact target's approach is searched, m."""


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def _normalised(tangent: np.ndarray) -> np.ndarray:
    return tangent / np.linalg.norm(tangent, axis=-1, keepdims=True)


def _front_probe(
    xy: np.ndarray, tangent: np.ndarray, geometry: dict, point: np.ndarray, direction: np.ndarray, heading: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For rear-axle poses [N]: (clearance, reference point [N, 2], its distance ahead of the VUT point along the
    heading) with the reference point on the target path where the VUT's nominal lateral line crosses it."""
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    vut_point = xy + geometry["along_m"] * tangent + geometry["left_m"] * normal
    denom = _cross(tangent[:, 0], tangent[:, 1], direction[0], direction[1])
    rel = point - vut_point
    with np.errstate(divide="ignore", invalid="ignore"):
        ahead = _cross(rel[:, 0], rel[:, 1], direction[0], direction[1]) / denom
    ahead = np.where(np.abs(denom) > 1e-9, ahead, np.inf)
    ref = vut_point + np.where(np.isfinite(ahead), ahead, 0.0)[:, None] * tangent
    centre = ref + geometry["centre_ahead_m"] * heading
    rect = xy + geometry["rear_to_centre_m"] * tangent
    clearance = rectangle_circle_clearance(
        rect[:, 0], rect[:, 1], tangent[:, 0], tangent[:, 1], geometry["half_length_m"], geometry["half_width_m"],
        centre[:, 0], centre[:, 1], geometry["radius_m"],
    )[0]  # fmt: skip
    return np.where(np.isfinite(ahead), clearance, np.inf), ref, ahead


def _refine(a: np.ndarray, b: np.ndarray, clearance_at) -> float:
    """Fraction in [0, 1] between poses `a` (clear) and `b` (touching) where `clearance_at(xy, tangent)` first
    reaches 0: one vectorised pass over SUBSAMPLES poses, then linear interpolation of the clearance."""
    frac = np.linspace(0.0, 1.0, SUBSAMPLES + 1)
    poses = a + frac[:, None] * (b - a)
    clearance = clearance_at(poses[:, :2], _normalised(poses[:, 2:4]))
    j = int(np.flatnonzero(clearance <= 0.0)[0])
    if j == 0:
        return 0.0
    c0, c1 = clearance[j - 1], clearance[j]
    return float(frac[j - 1] + (frac[j] - frac[j - 1]) * c0 / (c0 - c1)) if np.isfinite(c0 - c1) else float(frac[j])


def _pose(samples: np.ndarray, station_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Rear-axle position and unit tangent at a route station (linear between samples)."""
    k = min(max(station_m / SAMPLE_SPACING_M, 0.0), len(samples) - 1.0)
    i = min(int(k), len(samples) - 2)
    pose = samples[i] + (k - i) * (samples[i + 1] - samples[i])
    return pose[:2], pose[2:4] / np.hypot(*pose[2:4])


def front_first_contact(
    samples: np.ndarray, geometry: dict, point: np.ndarray, direction: np.ndarray, heading: np.ndarray | None = None
) -> tuple[float, np.ndarray, float]:
    """First route station (m) at which the target's contact circle, with its reference point on the target path
    (through `point` along unit `direction`) where the VUT's nominal lateral line meets it, touches the VUT
    rectangle; that reference point (world, m); and its distance ahead of the VUT's nominal point, m.

    `geometry`: along_m / left_m (the VUT's nominal point from the rear axle, simulated frame), rear_to_centre_m,
    half_length_m, half_width_m (the rectangle), centre_ahead_m (circle centre ahead of the reference point
    along the target's `heading`, default `direction`) and radius_m. A target moving along the VUT's lateral
    line (longitudinal tests) passes the line through its collision point across the VUT path as `direction`.
    """
    heading = direction if heading is None else heading

    def clearance_at(xy, tangent):
        return _front_probe(xy, tangent, geometry, point, direction, heading)[0]

    clearance = clearance_at(samples[:, :2], samples[:, 2:4])
    touching = np.flatnonzero(clearance <= 0.0)
    if len(touching) == 0:
        raise ValueError("the target's contact circle never touches the VUT on its nominal lateral line")
    i = int(touching[0])
    frac = _refine(samples[i - 1], samples[i], clearance_at) if i > 0 else 0.0
    station = (i - 1 + frac) * SAMPLE_SPACING_M if i > 0 else 0.0
    xy, tangent = _pose(samples, station)
    _, ref, ahead = _front_probe(xy[None], tangent[None], geometry, point, direction, heading)
    return station, ref[0], float(ahead[0])


def side_first_contact(
    samples: np.ndarray, station_m: float, geometry: dict, crossing: np.ndarray, direction: np.ndarray
) -> np.ndarray:
    """Side impacts: with the VUT at `station_m` (where its nominal side point crosses the target path at
    `crossing`), the reference point (world, m) at which the target's circle, coming along `direction`, first
    touches the VUT rectangle."""
    xy, tangent = _pose(samples, station_m)
    rect = xy + geometry["rear_to_centre_m"] * tangent

    def clearance_at(back_m: np.ndarray) -> np.ndarray:
        centre = crossing - np.outer(back_m, direction) + geometry["centre_ahead_m"] * direction
        return rectangle_circle_clearance(
            rect[0], rect[1], tangent[0], tangent[1], geometry["half_length_m"], geometry["half_width_m"],
            centre[:, 0], centre[:, 1], geometry["radius_m"],
        )[0]  # fmt: skip

    back = np.linspace(SIDE_SEARCH_M, 0.0, round(SIDE_SEARCH_M / 0.01) + 1)
    touching = np.flatnonzero(clearance_at(back) <= 0.0)
    if len(touching) == 0 or touching[0] == 0:
        raise ValueError("no first contact of a side-impact target along its path")
    fine = np.linspace(back[touching[0] - 1], back[touching[0]], SUBSAMPLES + 1)  # clear first, touching last
    clearance = clearance_at(fine)
    j = int(np.flatnonzero(clearance <= 0.0)[0])
    c0, c1 = clearance[j - 1], clearance[j]
    found = fine[j - 1] + (fine[j] - fine[j - 1]) * c0 / (c0 - c1)
    return crossing - found * direction


def side_first_contact_at(
    samples: np.ndarray, station_m: float, geometry: dict, crossing: np.ndarray, direction: np.ndarray
) -> tuple[float, np.ndarray, np.ndarray]:
    """Side impacts, exactly: starting from `station_m` (the nominal side point on the target path at
    `crossing`), the route station at which the circle's first touch (`side_first_contact`) has the reference
    point at the nominal length fraction (`geometry["along_m"]` from the rear axle). Secant iteration to 0.1 mm.

    Returns (station, reference point (world, m), reference point in the VUT frame from the rectangle centre).
    """
    anchor = crossing + direction  # a point of the path beyond the contact; the search starts behind it

    def miss(station: float) -> tuple[float, np.ndarray, np.ndarray]:
        xy, tangent = _pose(samples, station)
        ref = side_first_contact(samples, station, geometry, anchor, direction)
        rel = ref - xy
        local = np.array([rel @ tangent, -rel[0] * tangent[1] + rel[1] * tangent[0]])
        return local[0] - geometry["along_m"], ref, local - [geometry["rear_to_centre_m"], 0.0]

    s0, s1 = station_m, station_m + 0.05
    f0, ref, local = miss(s0)
    for _ in range(12):
        if abs(f0) < 1e-4:
            break
        f1, ref1, local1 = miss(s1)
        if f1 == f0:
            break
        s0, s1, f0, ref, local = s1, s1 - f1 * (s1 - s0) / (f1 - f0), f1, ref1, local1
    return s0, ref, local


def reference_point_at_first_contact(built: Sequence[Any], run: BatchRun) -> np.ndarray:
    """Where each test's target reference point is at the first contact of a traced run: [B, 2] (m ahead of the
    VUT rectangle centre, m left of it; simulated frame), NaN where the bodies never touch. `built`: the
    `ncap.build.BuiltTest`s of the batch, in order.

    Read from the trace (`simulate(..., trace=True)`): the VRU centre and the VUT pose at the first step whose
    clearance is <= 0, interpolated linearly within that step to the instant the clearance reaches 0
    (bisection), the centre shifted back to the reference point along the target's heading.
    """
    trace = run.trace
    if trace is None:
        raise ValueError("reference_point_at_first_contact needs a traced run (simulate(..., trace=True))")
    params = run.params
    out = np.full((len(built), 2), np.nan)
    names = ("ego_x_m", "ego_y_m", "ego_heading_x", "ego_heading_y")
    for b, item in enumerate(built):
        ego = np.column_stack([trace[n][:, b] for n in names] + [trace["vru_x_m"][:, b, 0], trace["vru_y_m"][:, b, 0]])
        half_length, half_width = params.half_length_m[b], params.half_width_m[b]
        radius = item.scenario.vrus[0].radius_m

        def clearance(rows: np.ndarray, hl=half_length, hw=half_width, r=radius) -> np.ndarray:
            heading = _normalised(rows[:, 2:4])
            return rectangle_circle_clearance(
                rows[:, 0], rows[:, 1], heading[:, 0], heading[:, 1], hl, hw, rows[:, 4], rows[:, 5], r
            )[0]

        touching = np.flatnonzero(clearance(ego) <= 0.0)
        if len(touching) == 0:
            continue
        k = int(touching[0])
        row = ego[k]
        if k > 0:
            lo, hi = 0.0, 1.0
            for _ in range(BISECTIONS):
                mid = 0.5 * (lo + hi)
                if clearance((ego[k - 1] + mid * (ego[k] - ego[k - 1]))[None])[0] <= 0.0:
                    hi = mid
                else:
                    lo = mid
            row = ego[k - 1] + hi * (ego[k] - ego[k - 1])
        heading = row[2:4] / np.hypot(*row[2:4])
        back = item.nominal.ref_behind_centre_m
        angle = item.nominal.target_heading_rad
        ref_x, ref_y = row[4] - back * np.cos(angle), row[5] - back * np.sin(angle)
        local = to_local_frame(row[0], row[1], heading[0], heading[1], ref_x, ref_y)
        out[b] = float(local[0]), float(local[1])
    return out

"""Recover a vrusim route (`Route` fields) from the ego's trajectory polyline, as `osc_motion.ego_trajectory`
writes it.

The polyline is read as: straight segments (vertex headings equal), then at most one turn (curved segments, all
turning the same way), then straight segments, and a last segment that is the run-out past the route end.
Each segment's arc length follows from its chord c and heading change a: c (a / 2) / sin(a / 2) (exact on an
arc). In the turn, the segments of the largest curvature are the arc (radius = length / angle); segments of
rising curvature before it and falling after it are clothoids (`clothoid_angle_deg` = their heading change,
`clothoid_entry_radius_m` from their length L and angle a: 1 / R_entry = 2 a / L - 1 / R). A trajectory that
begins inside the turn gives `start_in_turn_m`. Anything else is a UserInputError.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from vrusim.formats.xosc_model import WorldPose

STRAIGHT_RAD = 1e-7
"""A segment whose heading changes by less than this is straight, rad."""
ARC_CURVATURE_REL = 1e-4
"""Segments within this relative tolerance of the largest curvature belong to the arc."""
CHORD_HEADING_RAD = 1e-3
"""A segment's chord must point along the mean of its vertex headings within this, rad (no corners)."""
HIDDEN_ARC_DEG = 1.0
"""A trajectory that starts inside a plain arc: the unseen part of the turn is recorded as this much arc, deg."""

Fail = Callable[[str], Exception]


def _segments(vertices: tuple[WorldPose, ...], fail: Fail) -> tuple[np.ndarray, np.ndarray]:
    """(heading change rad, arc length m) of each segment."""
    xy = np.array([(v.x_m, v.y_m) for v in vertices])
    heading = np.array([v.heading_rad for v in vertices])
    turn = np.angle(np.exp(1j * np.diff(heading)))
    chord_vector = np.diff(xy, axis=0)
    chord = np.hypot(chord_vector[:, 0], chord_vector[:, 1])
    if np.any(chord <= 0.0):
        raise fail("has two equal consecutive vertices")
    direction = np.arctan2(chord_vector[:, 1], chord_vector[:, 0])
    if np.any(np.abs(np.angle(np.exp(1j * (direction - heading[:-1] - turn / 2)))) > CHORD_HEADING_RAD):
        raise fail("has a corner: its vertex headings (h) must follow the polyline's direction")
    half = np.where(np.abs(turn) < STRAIGHT_RAD, 1.0, turn / 2)
    length = np.where(np.abs(turn) < STRAIGHT_RAD, chord, chord * half / np.sin(half))
    return turn, length


def _contiguous(mask: np.ndarray, fail: Fail, what: str) -> tuple[int, int]:
    """[first, end) of the True entries of `mask`, which must be one run."""
    index = np.flatnonzero(mask)
    if len(index) and index[-1] - index[0] + 1 != len(index):
        raise fail(f"has more than one {what}")
    return (int(index[0]), int(index[-1]) + 1) if len(index) else (0, 0)


def _turn_fields(turn: np.ndarray, length: np.ndarray, starts_inside: bool, fail: Fail) -> dict[str, float]:
    """Route fields of the turn from its segments (heading changes rad, lengths m)."""
    if not (np.all(turn > 0) or np.all(turn < 0)):
        raise fail("turns both ways: a vrusim route has one left or right turn")
    curvature = np.abs(turn) / length
    lo, hi = _contiguous(curvature >= curvature.max() * (1 - ARC_CURVATURE_REL), fail, "arc")
    entry, arc, exit_ = slice(0, lo), slice(lo, hi), slice(hi, len(turn))
    radius = float(length[arc].sum() / np.abs(turn[arc]).sum())
    fields = {"radius_m": radius, "angle_deg": math.degrees(float(np.abs(turn[arc]).sum()))}
    if hi == len(turn) and lo == 0:  # a plain arc
        return fields
    if hi == len(turn):
        raise fail("has a clothoid into the turn but none out of it")
    if not np.all(np.diff(curvature[exit_]) < 0):
        raise fail("has a turn exit whose curvature does not fall steadily (not a clothoid)")
    angle, clothoid_m = float(np.abs(turn[exit_]).sum()), float(length[exit_].sum())
    entry_curvature = 2 * angle / clothoid_m - 1 / radius
    if entry_curvature <= 0:
        raise fail("has a turn exit that is not a clothoid from the arc's curvature")
    fields |= {"clothoid_angle_deg": math.degrees(angle), "clothoid_entry_radius_m": 1 / entry_curvature}
    seen_entry = float(length[entry].sum())
    if not starts_inside:
        if abs(float(np.abs(turn[entry]).sum()) - angle) > 1e-6 or abs(seen_entry - clothoid_m) > 1e-4:
            raise fail("has clothoids into and out of the turn that are not mirror images")
        return fields
    return fields | {"start_in_turn_m": clothoid_m - seen_entry if lo > 0 else clothoid_m}


def fit_route(vertices: tuple[WorldPose, ...], route_length_m: float | None, fail: Fail) -> dict[str, float | str]:
    """The `Route` fields of the ego trajectory `vertices` (forward driving, from the start).

    The last segment is the run-out past the route end when there are three or more vertices; the route's
    length is `route_length_m` when given (the stop trigger's travelled distance), else the polyline's up to
    the last vertex before the run-out. `fail(message)` makes the error naming the trajectory.
    """
    turn, length = _segments(vertices, fail)
    if len(turn) > 1:
        turn, length = turn[:-1], length[:-1]
    total = float(length.sum())
    if route_length_m is not None and len(vertices) > 2 and abs(route_length_m - total) > 1e-3:
        raise fail(f"ends its route at {total:.3f} m, but the stop trigger says {route_length_m:.3f} m")
    route: dict[str, float | str] = {"length_m": route_length_m if route_length_m is not None else total}
    curved = np.abs(turn) >= STRAIGHT_RAD
    if not curved.any():
        return route | {"kind": "straight"}
    first, end = _contiguous(curved, fail, "turn")
    fields = _turn_fields(turn[first:end], length[first:end], first == 0, fail)
    if first == 0 and "clothoid_angle_deg" not in fields:  # inside a plain arc: the unseen part is made up
        hidden = min(HIDDEN_ARC_DEG, 180.0 - fields["angle_deg"])
        fields |= {
            "angle_deg": fields["angle_deg"] + hidden,
            "start_in_turn_m": fields["radius_m"] * math.radians(hidden),
        }
    kind = "left" if turn[first] > 0 else "right"
    return route | fields | {"kind": kind, "turn_at_m": float(length[:first].sum())}

"""Drawn road geometry of a scenario: marked lines and paved surfaces as world-frame polylines (`road.lines`,
`road.surfaces`).

An imported OpenDRIVE road keeps its real network this way (`vrusim.formats.xodr_drawing`); figures draw it
instead of the generated `layout`. Only figures read these fields: the simulation, sensor and planners never do.
Points are `[x_m, y_m]` pairs in the world frame, each coordinate held to the `coordinate_m` bound; all points of
one road together to the `road_points` budget (docs/limits.md).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, Strict, field_validator

from vrusim.limits import excess
from vrusim.scenario.strict import StrictModel

_Number = Annotated[float, Strict()]
XY = Annotated[tuple[_Number, _Number], Strict(False)]
"""A world-frame point (x, y), m: a YAML list of two numbers."""


def _within_bounds(points: list[XY]) -> list[XY]:
    """The points, or a ValueError naming the first coordinate beyond the `coordinate_m` bound."""
    for index, point in enumerate(points):
        for value in point:
            reason = excess("coordinate_m", value)
            if reason is not None:
                raise ValueError(f"points[{index}]: {reason}")
    return points


class RoadLine(StrictModel):
    """A line on the road: an `edge` of the paved surface, a `lane` boundary between lanes of one direction, or the
    `centre` line between opposite directions; drawn `solid` or `broken` through `points` (at least two)."""

    kind: Literal["edge", "lane", "centre"]
    style: Literal["solid", "broken"] = "solid"
    points: list[XY] = Field(min_length=2, description="[[x_m, y_m], ...] in the world frame")

    @field_validator("points")
    @classmethod
    def _bounded(cls, points: list[XY]) -> list[XY]:
        return _within_bounds(points)


class RoadSurface(StrictModel):
    """A paved area: the closed outline through `points` (at least three; the last joins the first), filled."""

    points: list[XY] = Field(min_length=3, description="[[x_m, y_m], ...] in the world frame")

    @field_validator("points")
    @classmethod
    def _bounded(cls, points: list[XY]) -> list[XY]:
        return _within_bounds(points)


def point_count(lines: list[RoadLine] | None, surfaces: list[RoadSurface] | None) -> int:
    """All points of the drawn road."""
    return sum(len(item.points) for item in (*(lines or ()), *(surfaces or ())))


def points_excess(lines: list[RoadLine] | None, surfaces: list[RoadSurface] | None) -> str | None:
    """Why the drawn road has too many points (limit `road_points`), or None."""
    return excess("road_points", point_count(lines, surfaces))

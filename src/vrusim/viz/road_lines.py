"""Draw a scenario's own road geometry (`road.lines`, `road.surfaces`: an imported OpenDRIVE network) instead of
the generated layout.

Surfaces are filled in the road colour; lines are drawn in one collection per kind and style (edges 1.4 pt,
lane and centre lines 1.0 pt, broken: 6 pt dashes), white on a drawn surface, dark grey when the road has lines
but no surfaces (so they show on the verge colour).
"""

from __future__ import annotations

from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PolyCollection

from vrusim.scenario.schema import Road
from vrusim.viz import style

LINE_WIDTH_PT = {"edge": 1.4, "lane": 1.0, "centre": 1.0}
BROKEN_DASHES_PT = (0, (6, 6))


def has_drawn_road(road: Road) -> bool:
    """Whether the road brings its own lines or surfaces to draw."""
    return road.lines is not None or road.surfaces is not None


def draw_road_lines(ax: Axes, road: Road, surface_zorder: float, line_zorder: float) -> list:
    """Add the road's surfaces and lines to `ax`; return the collections added (surfaces first)."""
    artists: list = []
    if road.surfaces:
        polygons = [surface.points for surface in road.surfaces]
        fill = PolyCollection(polygons, closed=True, facecolors=style.ROAD, edgecolors="none", zorder=surface_zorder)
        artists.append(ax.add_collection(fill, autolim=False))
    colour = style.MARKING if road.surfaces else style.ROAD
    groups: dict[tuple[str, str], list] = {}
    for line in road.lines or ():
        groups.setdefault((line.kind, line.style), []).append(line.points)
    for (kind, line_style), segments in groups.items():
        collection = LineCollection(
            segments,
            colors=colour,
            linewidths=LINE_WIDTH_PT[kind],
            linestyles="solid" if line_style == "solid" else [BROKEN_DASHES_PT],
            capstyle="butt",
            zorder=line_zorder,
        )
        collection.set_label(f"road {kind} ({line_style})")
        artists.append(ax.add_collection(collection, autolim=False))
    return artists

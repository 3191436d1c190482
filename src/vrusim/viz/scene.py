"""A bird's-eye picture of one recording at one time, in the style of the paper's snapshot figures.

Road and lane markings (the generated layout, or an imported road's own lines: `viz.road_lines`), obstruction
vehicles, the roadside unit with its V2X ranges (V2X enabled only), planned ego route and VRU paths (dashed),
travelled trajectories up to t, the sensor sector (blue, translucent, apex at the centre of the leading bumper,
cut where obstacles block the line of sight), the ego rectangle with a heading mark, VRU circles at their
footprint radius (ring: perceived by the sensor, blue; by V2X, purple dashed), an impact star and a time label.

`SceneArtists` builds every artist once; `update(index)` moves the moving ones to a trace sample, so an
animation redraws without rebuilding. World frame, metres, equal aspect.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Polygon, Rectangle

from vrusim.scenario.schema import Road, Scenario
from vrusim.sim.observation import SOURCE_SENSOR, SOURCE_V2X
from vrusim.viz import style
from vrusim.viz.literal_text import literal_texts
from vrusim.viz.recording import Recording
from vrusim.viz.road_lines import draw_road_lines, has_drawn_road

# z-order of the layers, bottom to top
_Z_ROAD, _Z_MARK, _Z_RANGE, _Z_PATH, _Z_SECTOR, _Z_BODY, _Z_RING, _Z_TOP = 0, 1, 2, 3, 4, 5, 6, 7
_FOLLOW_AHEAD = 0.25
"""In a following view the ego sits this fraction of the window width behind the window centre."""


# ----------------------------------------------------------------------------------------------- view window


@dataclass(frozen=True)
class ViewWindow:
    """What part of the world a scene shows: a fixed box, or a `width_m` × `height_m` window following the
    ego (looking ahead along its heading) inside `box` when the action is too long for one picture."""

    box: tuple[float, float, float, float]
    """x_min, x_max, y_min, y_max of everything worth showing, m."""
    width_m: float
    height_m: float
    follow: bool

    def limits(self, recording: Recording, index: int) -> tuple[float, float, float, float]:
        """Axes limits (x_min, x_max, y_min, y_max), m, at trace sample `index`."""
        x0, x1, y0, y1 = self.box
        if not self.follow:
            cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        else:
            trace = recording.trace
            cx = trace["ego_x_m"][index] + _FOLLOW_AHEAD * self.width_m * trace["ego_heading_x"][index]
            cy = trace["ego_y_m"][index] + _FOLLOW_AHEAD * self.height_m * trace["ego_heading_y"][index]
            cx = _clamp(cx, x0 + self.width_m / 2, x1 - self.width_m / 2)
            cy = _clamp(cy, y0 + self.height_m / 2, y1 - self.height_m / 2)
        return cx - self.width_m / 2, cx + self.width_m / 2, cy - self.height_m / 2, cy + self.height_m / 2


def _clamp(value: float, low: float, high: float) -> float:
    return (low + high) / 2 if low > high else min(max(value, low), high)


def view_window(
    recordings: list[Recording] | Recording,
    max_width_m: float = 80.0,
    margin_m: float = 3.0,
    max_aspect: float = 4.0,
) -> ViewWindow:
    """One window for all `recordings` (so panels compare): the ego's whole run, each VRU while it is within
    reach of the ego (twice the sensor range, at least 40 m) and at its start, obstacles, the RSU and the road's cross
    section; following the ego when wider than `max_width_m`; width / height at most `max_aspect`."""
    recordings = [recordings] if isinstance(recordings, Recording) else list(recordings)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    for rec in recordings:
        scenario, trace = rec.scenario, rec.trace
        half = scenario.ego.length_m / 2
        for sign in (-1, 1):
            xs.append(trace["ego_x_m"] + sign * half)
            ys.append(trace["ego_y_m"] + sign * half)
        reach = max(2 * scenario.sensor.effective_range_m, 40.0)
        for k, vru in enumerate(scenario.vrus):
            vx, vy = trace["vru_x_m"][:, k], trace["vru_y_m"][:, k]
            near = np.hypot(vx - trace["ego_x_m"], vy - trace["ego_y_m"]) <= reach
            near[0] = True
            r = vru.footprint_m
            xs += [vx[near] - r, vx[near] + r]
            ys += [vy[near] - r, vy[near] + r]
        for box in scenario.obstacles:
            size = max(box.length_m, box.width_m) / 2
            xs.append(np.array([box.centre.x_m - size, box.centre.x_m + size]))
            ys.append(np.array([box.centre.y_m - size, box.centre.y_m + size]))
        if scenario.v2x.enabled and scenario.v2x.rsu is not None:
            xs.append(np.array([scenario.v2x.rsu.x_m]))
            ys.append(np.array([scenario.v2x.rsu.y_m]))
        if not has_drawn_road(scenario.road):  # the layout's cross section (an imported road: the actors frame it)
            road = scenario.road.lane_width_m + 1.0
            ys.append(np.array([-road, road]))
    x = np.concatenate(xs)
    y = np.concatenate(ys)
    x0, x1 = float(x.min()) - margin_m, float(x.max()) + margin_m
    y0, y1 = float(y.min()) - margin_m, float(y.max()) + margin_m
    width, height = x1 - x0, y1 - y0
    follow = width > max_width_m
    if follow:
        width = max_width_m
        height = min(height, width)
    # keep panels readable: neither a thin strip nor a tall column
    height = max(height, width / max_aspect)
    width = max(width, height / 1.5)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if not follow:
        x0, x1 = cx - width / 2, cx + width / 2
    if y1 - y0 < height:
        y0, y1 = cy - height / 2, cy + height / 2
    return ViewWindow((x0, x1, y0, y1), width, height, follow)


# ----------------------------------------------------------------------------------------------- static layers


def _draw_road(ax: Axes, road: Road) -> None:
    """Road surface, edge lines and dashed centre line(s); a four-arm junction centred on the origin. A road with
    its own lines or surfaces (imported) is drawn from them instead (`viz.road_lines`)."""
    if has_drawn_road(road):
        draw_road_lines(ax, road, _Z_ROAD, _Z_MARK)
        return
    w, half = road.lane_width_m, road.length_m / 2
    mark = {"color": style.MARKING, "zorder": _Z_MARK, "solid_capstyle": "butt"}
    dashed = {**mark, "lw": 1.0, "dashes": (6, 6)}
    ax.add_patch(Rectangle((-half, -w), 2 * half, 2 * w, facecolor=style.ROAD, edgecolor="none", zorder=_Z_ROAD))
    if road.layout == "straight":
        for y in (-w, w):
            ax.plot([-half, half], [y, y], lw=1.4, **mark)
        ax.plot([-half, half], [0, 0], **dashed)
        return
    ax.add_patch(Rectangle((-w, -half), 2 * w, 2 * half, facecolor=style.ROAD, edgecolor="none", zorder=_Z_ROAD))
    for sign in (-1, 1):  # each arm: edge lines up to the junction, centre line, stop line
        for edge in (-w, w):
            ax.plot([sign * w, sign * half], [edge, edge], lw=1.4, **mark)
            ax.plot([edge, edge], [sign * w, sign * half], lw=1.4, **mark)
        ax.plot([sign * w, sign * half], [0, 0], **dashed)
        ax.plot([0, 0], [sign * w, sign * half], **dashed)
    for x0, y0, x1, y1 in ((-w, -w, -w, 0), (w, 0, w, w), (0, w, -w, w), (w, -w, 0, -w)):  # stop lines
        ax.plot([x0, x1], [y0, y1], lw=2.2, **mark)


def _rectangle_xy(cx: float, cy: float, hx: float, hy: float, length_m: float, width_m: float) -> np.ndarray:
    """Corners [4, 2] of a rectangle centred at (cx, cy) with unit heading (hx, hy)."""
    u = np.array([hx, hy]) * length_m / 2
    v = np.array([-hy, hx]) * width_m / 2
    c = np.array([cx, cy])
    return np.array([c - u - v, c + u - v, c + u + v, c - u + v])


SECTOR_RAY_STEP_DEG = 0.5
"""Angular spacing of the rays that outline the drawn sensor field of view, degrees."""


def _box_frames(scenario: Scenario) -> np.ndarray:
    """Each obstacle as (centre x, centre y, heading x, heading y, half length, half width), [M, 6]."""
    rows = []
    for box in scenario.obstacles:
        heading = math.radians(box.centre.heading_deg)
        rows.append(
            (box.centre.x_m, box.centre.y_m, math.cos(heading), math.sin(heading), box.length_m / 2, box.width_m / 2)
        )
    return np.array(rows, dtype=float).reshape(-1, 6)


def _ray_box_distances(apex: np.ndarray, directions: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Distance along each unit ray [N, 2] from `apex` to where it first meets the closed box (inf: misses)."""
    cx, cy, hx, hy, half_length, half_width = box
    dx, dy = apex[0] - cx, apex[1] - cy
    origin = np.array([dx * hx + dy * hy, dy * hx - dx * hy])  # apex in the box frame
    local = np.stack([directions @ np.array([hx, hy]), directions @ np.array([-hy, hx])], axis=1)
    half = np.array([half_length, half_width])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (-half - origin) / local, (half - origin) / local
    inside_slab = np.abs(origin) <= half  # a ray parallel to a slab is inside it for all t, or never
    near = np.where(local == 0, np.where(inside_slab, -np.inf, np.inf), np.minimum(t1, t2))
    far = np.where(local == 0, np.where(inside_slab, np.inf, -np.inf), np.maximum(t1, t2))
    enter, leave = near.max(axis=1), far.min(axis=1)
    hit = (leave >= enter) & (leave >= 0)
    return np.where(hit, np.maximum(enter, 0.0), np.inf)


def visible_sector_xy(
    apex: np.ndarray, heading_deg: float, fov_deg: float, range_m: float, boxes: np.ndarray
) -> np.ndarray:
    """Outline [N, 2] of the part of the sensor sector the apex sees: rays every `SECTOR_RAY_STEP_DEG`, each
    cut where it first meets an obstacle (as the sensor's line-of-sight model, `vrusim.sim.sensing.occlusion`)."""
    count = max(2, math.ceil(fov_deg / SECTOR_RAY_STEP_DEG) + 1)
    angles = np.radians(heading_deg + np.linspace(-fov_deg / 2, fov_deg / 2, count))
    directions = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    reach = np.full(count, float(range_m))
    for box in boxes:
        reach = np.minimum(reach, _ray_box_distances(apex, directions, box))
    points = apex + directions * reach[:, None]
    return points if fov_deg >= 360 else np.vstack([apex, points])


def _draw_obstacles(ax: Axes, scenario: Scenario) -> None:
    for box in scenario.obstacles:
        heading = math.radians(box.centre.heading_deg)
        xy = _rectangle_xy(
            box.centre.x_m, box.centre.y_m, math.cos(heading), math.sin(heading), box.length_m, box.width_m
        )
        ax.add_patch(
            Polygon(
                xy, closed=True, facecolor=style.OBSTACLE_FACE, edgecolor=style.OBSTACLE_EDGE, lw=0.8, zorder=_Z_BODY
            )
        )


def _draw_v2x(ax: Axes, scenario: Scenario) -> None:
    """RSU marker, its communication range (filled, dashed edge) and perception coverage (dotted)."""
    v2x = scenario.v2x
    if not v2x.enabled or v2x.rsu is None:
        return
    centre = (v2x.rsu.x_m, v2x.rsu.y_m)
    ax.add_patch(
        Circle(
            centre,
            v2x.comm_range_m,
            facecolor=(*_rgb(style.V2X), 0.07),
            edgecolor=style.V2X,
            lw=0.9,
            ls="--",
            zorder=_Z_RANGE,
        )
    )
    ax.add_patch(Circle(centre, v2x.coverage_range_m, fill=False, edgecolor=style.V2X, lw=0.8, ls=":", zorder=_Z_RANGE))
    ax.plot(*centre, marker="^", ms=8, color=style.V2X, mec="white", mew=0.8, zorder=_Z_TOP, ls="none")
    ax.annotate("RSU", centre, xytext=(5, 4), textcoords="offset points", fontsize=7, color=style.V2X, zorder=_Z_TOP)


def _rgb(colour: str) -> tuple[float, float, float]:
    from matplotlib.colors import to_rgb

    return to_rgb(colour)


# ----------------------------------------------------------------------------------------------- moving layers


class SceneArtists:
    """Every artist of a scene, built once on `ax`; `update(index)` moves them to trace sample `index`."""

    def __init__(self, ax: Axes, recording: Recording, window: ViewWindow | None = None, label: bool = True) -> None:
        self.ax, self.recording = ax, recording
        self.window = window or view_window(recording)
        scenario = recording.scenario
        self.n_vrus = len(scenario.vrus)
        ax.set_facecolor(style.GROUND)
        ax.set_aspect("equal", adjustable="box")
        _draw_road(ax, scenario.road)
        _draw_obstacles(ax, scenario)
        _draw_v2x(ax, scenario)
        route = recording.ego_route_xy_m()
        ax.plot(route[:, 0], route[:, 1], color=style.PLANNED, lw=0.9, ls=(0, (4, 3)), zorder=_Z_PATH)
        for vru, path in zip(scenario.vrus, recording.vru_paths_xy_m(), strict=True):
            ax.plot(path[:, 0], path[:, 1], color=style.vru_colour(vru.type), lw=0.9, ls=(0, (4, 3)), zorder=_Z_PATH)

        self.ego_track = ax.plot([], [], color=style.EGO_FACE, lw=1.6, alpha=0.8, zorder=_Z_PATH)[0]
        self.vru_tracks = [
            ax.plot([], [], color=style.vru_colour(v.type), lw=1.6, alpha=0.9, zorder=_Z_PATH)[0] for v in scenario.vrus
        ]
        sensor = scenario.sensor
        self.boxes = _box_frames(scenario)
        self.sector = Polygon(
            np.zeros((3, 2)), closed=True, facecolor=style.SENSOR_FACE, edgecolor=style.SENSOR_EDGE, lw=0.8
        )
        self.sector.set_zorder(_Z_SECTOR)
        self.sector.set_visible(sensor.enabled)
        ax.add_patch(self.sector)
        self.ego = Polygon(np.zeros((4, 2)), closed=True, facecolor=style.EGO_FACE, edgecolor=style.EGO_EDGE, lw=1.0)
        self.ego.set_zorder(_Z_BODY)
        self.nose = Polygon(np.zeros((3, 2)), closed=True, facecolor="white", edgecolor="none", zorder=_Z_BODY + 0.1)
        ax.add_patch(self.ego)
        ax.add_patch(self.nose)
        self.vrus, self.sensor_rings, self.v2x_rings = [], [], []
        for vru in scenario.vrus:
            r = vru.footprint_m
            self.vrus.append(
                ax.add_patch(Circle((0, 0), r, facecolor=style.vru_colour(vru.type), edgecolor="black", lw=0.7))
            )
            self.vrus[-1].set_zorder(_Z_BODY)
            self.sensor_rings.append(
                ax.add_patch(Circle((0, 0), r + 0.35, fill=False, edgecolor=style.DETECTED_SENSOR, lw=1.6))
            )
            self.v2x_rings.append(
                ax.add_patch(Circle((0, 0), r + 0.8, fill=False, edgecolor=style.V2X, lw=1.4, ls=(0, (2, 1.5))))
            )
            self.sensor_rings[-1].set_zorder(_Z_RING)
            self.v2x_rings[-1].set_zorder(_Z_RING)
        self.impact = ax.plot(
            [], [], marker="*", ms=13, alpha=0.9, color=style.IMPACT, mec="black", mew=0.6, ls="none"
        )[0]
        self.impact.set_zorder(_Z_TOP)
        impact_s = recording.events_s.get("impact")
        self.impact_index = None if impact_s is None else recording.nearest_index(impact_s)
        self.label = ax.text(
            0.01,
            0.97,
            "",
            transform=ax.transAxes,
            va="top",
            ha="left",
            fontsize=8,
            zorder=_Z_TOP + 1,
            bbox={"boxstyle": "round,pad=0.25", "facecolor": "white", "edgecolor": "#999999", "alpha": 0.9},
        )
        self.label.set_visible(label)
        ax.tick_params(labelsize=7)
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)

    def update(self, index: int) -> None:
        """Move the moving artists to trace sample `index` (detections: what was decided at that time)."""
        rec, trace = self.recording, self.recording.trace
        scenario = rec.scenario
        decided = rec.decision_index(index)
        cx, cy = float(trace["ego_x_m"][index]), float(trace["ego_y_m"][index])
        hx, hy = float(trace["ego_heading_x"][index]), float(trace["ego_heading_y"][index])
        length, width = scenario.ego.length_m, scenario.ego.width_m
        self.ego.set_xy(_rectangle_xy(cx, cy, hx, hy, length, width))
        front = np.array([cx + hx * length / 2, cy + hy * length / 2])
        ahead, side = np.array([hx, hy]), np.array([-hy, hx])
        nose_depth = min(1.2, 0.4 * length)
        self.nose.set_xy(
            [
                front - 0.15 * ahead,
                front - nose_depth * ahead + 0.3 * width * side,
                front - nose_depth * ahead - 0.3 * width * side,
            ]
        )
        sensor = scenario.sensor
        heading_deg = math.degrees(math.atan2(hy, hx))
        self.sector.set_xy(visible_sector_xy(front, heading_deg, sensor.fov_deg, sensor.effective_range_m, self.boxes))
        self.ego_track.set_data(trace["ego_x_m"][: index + 1], trace["ego_y_m"][: index + 1])
        for k in range(self.n_vrus):
            x, y = float(trace["vru_x_m"][index, k]), float(trace["vru_y_m"][index, k])
            source = int(trace["vru_source"][decided, k])
            self.vrus[k].set_center((x, y))
            self.sensor_rings[k].set_center((x, y))
            self.sensor_rings[k].set_visible(bool(source & SOURCE_SENSOR))
            self.v2x_rings[k].set_center((x, y))
            self.v2x_rings[k].set_visible(bool(source & SOURCE_V2X))
            self.vru_tracks[k].set_data(trace["vru_x_m"][: index + 1, k], trace["vru_y_m"][: index + 1, k])
        if self.impact_index is not None and index >= self.impact_index:
            k = int(
                np.argmin(
                    np.hypot(trace["vru_x_m"][index, : self.n_vrus] - cx, trace["vru_y_m"][index, : self.n_vrus] - cy)
                )
            )
            vx, vy = float(trace["vru_x_m"][index, k]), float(trace["vru_y_m"][index, k])
            gap = max(math.hypot(cx - vx, cy - vy), 1e-9)
            reach = min(scenario.vrus[k].footprint_m, gap)  # on the footprint edge facing the ego
            self.impact.set_data([vx + (cx - vx) * reach / gap], [vy + (cy - vy) * reach / gap])
        else:
            self.impact.set_data([], [])
        mode = rec.mode_names[int(trace["planner_mode"][decided])] if rec.mode_names else ""
        night = " · night" if scenario.sensor.lighting == "night" else ""
        self.label.set_text(
            f"t = {trace['t_s'][index]:.2f} s · ego {trace['ego_speed_mps'][index]:.1f} m/s · {mode}{night}"
        )
        x0, x1, y0, y1 = self.window.limits(rec, index)
        self.ax.set_xlim(x0, x1)
        self.ax.set_ylim(y0, y1)

    def moving_artists(self) -> list:
        """The artists `update` changes, bottom to top (for blitting over a static background)."""
        artists = [self.ego_track, *self.vru_tracks, self.sector, self.ego, self.nose, *self.vrus]
        artists += [*self.sensor_rings, *self.v2x_rings, self.impact, self.label]
        return sorted(artists, key=lambda a: a.get_zorder())

    def update_time(self, t_s: float) -> None:
        """Move to the last sample at or before `t_s`."""
        self.update(self.recording.index_at(t_s))

    def set_recording(self, recording: Recording) -> None:
        """Follow a newer recording of the same scenario (a growing episode: more samples, new events); the static
        layers stay as drawn. Call `update` next."""
        self.recording = recording
        impact_s = recording.events_s.get("impact")
        self.impact_index = None if impact_s is None else recording.nearest_index(impact_s)


def legend_handles(recordings: list[Recording]) -> tuple[list, list[str]]:
    """Proxy artists and labels explaining a scene's layers (only the VRU types and layers present)."""
    handles: list = [
        Patch(facecolor=style.EGO_FACE, edgecolor=style.EGO_EDGE, label="ego vehicle"),
        Patch(facecolor=style.SENSOR_FACE, edgecolor=style.SENSOR_EDGE, label="sensor FOV"),
    ]
    types = dict.fromkeys(str(v.type) for r in recordings for v in r.scenario.vrus)
    for vru_type in types:
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                ls="none",
                ms=8,
                mfc=style.vru_colour(vru_type),
                mec="black",
                label=vru_type.replace("_", "-"),
            )
        )
    handles.append(
        Line2D(
            [], [], marker="o", ls="none", ms=10, mfc="none", mec=style.DETECTED_SENSOR, mew=1.6, label="seen by sensor"
        )
    )
    if any(r.scenario.v2x.enabled for r in recordings):
        handles.append(
            Line2D([], [], marker="o", ls="none", ms=11, mfc="none", mec=style.V2X, mew=1.4, label="known via V2X")
        )
        handles.append(Patch(facecolor=(*_rgb(style.V2X), 0.1), edgecolor=style.V2X, ls="--", label="RSU comm. range"))
    if any(r.scenario.obstacles for r in recordings):
        handles.append(Patch(facecolor=style.OBSTACLE_FACE, edgecolor=style.OBSTACLE_EDGE, label="obstruction"))
    handles.append(Line2D([], [], color=style.PLANNED, lw=0.9, ls=(0, (4, 3)), label="planned path"))
    handles.append(Line2D([], [], color=style.EGO_FACE, lw=1.6, label="travelled"))
    if any("impact" in r.events_s for r in recordings):
        handles.append(Line2D([], [], marker="*", ls="none", ms=12, color=style.IMPACT, mec="black", label="impact"))
    return handles, [h.get_label() for h in handles]


# ----------------------------------------------------------------------------------------------- entry points


def draw_scene(ax: Axes, recording: Recording, t_s: float, window: ViewWindow | None = None) -> SceneArtists:
    """Draw `recording` at time `t_s` (last sample at or before it) on `ax`; return the artists for updates."""
    artists = SceneArtists(ax, recording, window)
    artists.update_time(t_s)
    return artists


def scene_figure_size_in(width_in: float, window: ViewWindow) -> tuple[float, float]:
    """Width and height, inches, of a `scene_figure` `width_in` wide showing `window` (legend room included)."""
    return width_in, max(width_in * window.height_m / window.width_m + 1.3, 2.5)


class ScenePanel:
    """`scene_figure`'s content (scene axes, title, legend below) on an empty `figure` with a constrained layout;
    `show` redraws it in place for a newer recording of the same scenario (a growing episode), so one figure can
    follow a run step by step: the static layers are drawn once, the legend is rebuilt only when its entries
    change (an impact adds one)."""

    def __init__(self, figure: Figure, recording: Recording, window: ViewWindow) -> None:
        self.figure = figure
        ax = figure.add_subplot()
        self.artists = SceneArtists(ax, recording, window)
        ax.set_title(recording.scenario.name, fontsize=9, loc="left")
        self._legend: Legend | None = None
        self._labels: list[str] = []

    def show(self, recording: Recording, t_s: float) -> None:
        """Draw `recording` at time `t_s`, s (last sample at or before it)."""
        self.artists.set_recording(recording)
        handles, labels = legend_handles([recording])
        if labels != self._labels:
            if self._legend is not None:
                self._legend.remove()
            self._legend = self.figure.legend(
                handles, labels, loc="outside lower center", ncol=min(len(handles), 6), fontsize=7, frameon=False
            )
            self._labels = labels
        self.artists.update_time(t_s)


def scene_figure(
    recording: Recording, t_s: float, width_in: float = 9.0, dpi: float = 100.0, window: ViewWindow | None = None
) -> Figure:
    """A one-panel Figure (Agg canvas, no pyplot state) of `recording` at `t_s`, with a legend below; the view
    fits the whole run unless a `window` is given."""
    window = window if window is not None else view_window(recording)
    fig = Figure(figsize=scene_figure_size_in(width_in, window), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    ScenePanel(fig, recording, window).show(recording, t_s)
    return literal_texts(fig)

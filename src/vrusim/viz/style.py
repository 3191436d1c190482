"""Colours and labels shared by the scene, snapshot, time-series and animation figures (one table each)."""

from __future__ import annotations

from collections.abc import Sequence

from vrusim.viz.recording import Recording

GROUND = "#e9eee2"
"""Verge / background."""
ROAD = "#6e7175"
MARKING = "#ffffff"

EGO_FACE = "#2b6cb0"
"""Ego rectangle fill (a solid, opaque blue-grey; the sensor sector is a lighter translucent blue)."""
EGO_EDGE = "#12355e"
SENSOR_FACE = (0.15, 0.45, 1.0, 0.22)
"""Sensor sector fill: blue, translucent (RGBA)."""
SENSOR_EDGE = (0.15, 0.45, 1.0, 0.7)
V2X = "#8e44ad"
"""Roadside unit, its communication range and the V2X detection ring."""
OBSTACLE_FACE = "#9aa3ad"
OBSTACLE_EDGE = "#3d4650"
PLANNED = "#333333"
IMPACT = "#e01b24"

VRU_COLOURS: dict[str, str] = {
    "pedestrian": "#f28e2b",
    "cyclist": "#59a14f",
    "e_scooter": "#b07aa1",
    "motorcyclist": "#e15759",
}
"""VRU circle fill per VRU type."""
DETECTED_SENSOR = "#1f5fbf"
"""Ring around a VRU the onboard sensor perceives."""

MODE_COLOURS: dict[str, str] = {
    "cruise": "#cfe8cf",
    "hold": "#e0e0e0",
    "pre_slow": "#ffe08a",
    "yield": "#ffe08a",
    "warning": "#ffe08a",
    "follow": "#a9c8ef",
    "partial_brake": "#f7b267",
    "stop": "#f7b267",
    "emergency_brake": "#f08080",
    "full_brake": "#f08080",
}
"""Planner-state band colour per mode name (green: cruising, yellow: caution, blue: following, red: braking)."""
_SPARE_MODE_COLOURS = ("#d4b9da", "#c7e9c0", "#fdd0a2", "#bcbddc", "#d9d9d9")

EVENT_STYLES: dict[str, tuple[str, str]] = {
    "first_perception": ("#1f5fbf", ":"),
    "brake_onset": ("#d97706", "--"),
    "impact": (IMPACT, "-"),
    "closest_approach": ("#2e7d32", "-."),
}
"""(colour, line style) of each key event's marker."""

RECORDING_COLOURS = ("#222222", "#1b9e77", "#d95f02", "#7570b3", "#e7298a")
"""Line colour of the 1st, 2nd, ... recording in an overlay."""


def mode_colour(name: str, index: int = 0) -> str:
    """Band colour of a planner mode (known names from MODE_COLOURS, others from a spare cycle by index)."""
    return MODE_COLOURS.get(name, _SPARE_MODE_COLOURS[index % len(_SPARE_MODE_COLOURS)])


def vru_colour(vru_type: str) -> str:
    """Circle fill of a VRU type."""
    return VRU_COLOURS.get(str(vru_type), "#888888")


def recording_labels(recordings: Sequence[Recording]) -> list[str]:
    """Short row / legend labels: "V2X off" / "V2X on" when all share one scenario name, else name and V2X."""
    names = {r.scenario.name for r in recordings}
    v2x = [f"V2X {'on' if r.scenario.v2x.enabled else 'off'}" for r in recordings]
    if len(names) == 1 and len(set(v2x)) == len(v2x):
        return v2x
    return [f"{r.scenario.name} · {label}" for r, label in zip(recordings, v2x, strict=True)]

"""One simulated variant kept whole for pictures: scenario, per-step trace, summary row and key events.

Figures, animations and reports draw from a `Recording`, never from the engine directly, so they all show the
same run. Trace row i holds the state at `t_s[i]`; row -1 is the initial state, prepended here so that a
picture at t = 0 exists.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from vrusim.engine.simulate import BatchRun, simulate
from vrusim.geometry.paths import PathSpec, sample_path, sample_polyline
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.routes import ego_route_spec, vru_path_spec
from vrusim.scenario.schema import Scenario
from vrusim.sim.state import initial_ego, initial_vrus

KEY_EVENT_LABELS: dict[str, str] = {
    "first_perception": "first perception",
    "brake_onset": "brake onset",
    "impact": "impact",
    "closest_approach": "closest approach",
}
"""Display label of each key event name."""

DECISION_COLUMNS = ("vru_detected", "vru_source", "vru_v2x_age_s", "planner_mode", "ego_command_mps2")
"""Trace columns decided at the start of a step: row i holds what was decided at time t_s[i - 1] (row 0
repeats row 1, the decision at t = 0), while every other column holds the state at t_s[i]."""


@dataclass(frozen=True)
class Recording:
    """A single variant's run: `trace` maps column name → array [T] (ego) or [T, V] (per VRU)."""

    scenario: Scenario
    trace: dict[str, np.ndarray]
    summary: dict
    mode_names: tuple[str, ...]
    events_s: dict[str, float] = field(default_factory=dict)

    @property
    def t_s(self) -> np.ndarray:
        """Sample times, s (first sample t = 0)."""
        return self.trace["t_s"]

    def index_at(self, t_s: float) -> int:
        """Index of the last sample at or before `t_s` (clamped to the recorded span)."""
        return int(np.clip(np.searchsorted(self.t_s, t_s + 1e-9, side="right") - 1, 0, len(self.t_s) - 1))

    def nearest_index(self, t_s: float) -> int:
        """Index of the sample nearest to `t_s` (clamped to the recorded span)."""
        return int(np.argmin(np.abs(self.t_s - t_s)))

    def decision_index(self, index: int) -> int:
        """Row of the `DECISION_COLUMNS` decided at sample `index`'s time (the next row; the last row stays)."""
        return min(index + 1, len(self.t_s) - 1)

    def decisions(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """A decision column aligned with the time it was decided: (t_s [T-1], values [T-1, ...])."""
        return self.t_s[:-1], self.trace[name][1:]

    def key_moments(self, include_start: bool = True) -> list[tuple[str, float]]:
        """(label, t_s) of the start (t = 0) and each key event in time order; events at the same time are
        merged into one moment whose label joins theirs with " + "."""
        events = [("start", 0.0)] if include_start else []
        events += [(KEY_EVENT_LABELS[name], t) for name, t in self.events_s.items()]
        moments: list[tuple[str, float]] = []
        for label, t in sorted(events, key=lambda item: item[1]):
            if moments and abs(moments[-1][1] - t) < 1e-6:
                moments[-1] = (f"{moments[-1][0]} + {label}", moments[-1][1])
            else:
                moments.append((label, t))
        return moments

    def ego_route_xy_m(self) -> np.ndarray:
        """The ego's planned route as points [N, 2], m."""
        return ego_route_xy_m(self.scenario)

    def vru_paths_xy_m(self) -> list[np.ndarray]:
        """Each VRU's prescribed path as points [N, 2], m."""
        return vru_paths_xy_m(self.scenario)


def ego_route_xy_m(scenario: Scenario) -> np.ndarray:
    """The ego's planned route as points [N, 2], m."""
    return sample_path(ego_route_spec(scenario.ego))[:, :2]


def vru_paths_xy_m(scenario: Scenario) -> list[np.ndarray]:
    """Each VRU's prescribed path as points [N, 2], m."""
    paths = []
    for vru in scenario.vrus:
        spec = vru_path_spec(vru)
        points = sample_path(spec) if isinstance(spec, PathSpec) else sample_polyline(spec)
        paths.append(points[:, :2])
    return paths


def record(scenarios: Sequence[Scenario]) -> list[Recording]:
    """Simulate the scenarios as one traced batch; one Recording per scenario."""
    run = simulate(list(scenarios), trace=True)
    return recordings_of(run, scenarios)


def recordings_of(run: BatchRun, scenarios: Sequence[Scenario]) -> list[Recording]:
    """Split a traced batch run of `scenarios` (in batch order) into one Recording per variant."""
    if run.trace is None:
        raise ValueError("recordings need a traced run: simulate(..., trace=True)")
    if len(scenarios) != run.params.size:
        raise ValueError(f"recordings_of: {len(scenarios)} scenarios for a batch of {run.params.size} variants")
    rows = summary_rows(run)
    first = _initial_row(run)
    per_variant = {name: values for name, values in run.trace.items() if name != "t_s"}
    recordings = []
    for b, (scenario, row) in enumerate(zip(scenarios, rows, strict=True)):
        trace = {name: np.concatenate([first[name][b : b + 1], values[:, b]]) for name, values in per_variant.items()}
        trace["t_s"] = np.concatenate([[0.0], run.trace["t_s"]])
        trace = _trim(trace, row)
        recordings.append(Recording(scenario, trace, row, run.mode_names, key_events(row, trace)))
    return recordings


def _initial_row(run: BatchRun) -> dict[str, np.ndarray]:
    """The state at t = 0 in the trace's columns; planner outputs, clearance and TTC as of the first step."""
    params = run.params
    ego, vrus = initial_ego(params), initial_vrus(params)
    first = {name: values[0] for name, values in run.trace.items() if name != "t_s"}
    first.update(
        ego_x_m=ego.centre_x_m,
        ego_y_m=ego.centre_y_m,
        ego_heading_x=ego.heading_x,
        ego_heading_y=ego.heading_y,
        ego_speed_mps=ego.speed_mps,
        ego_accel_mps2=ego.accel_mps2,
        ego_station_m=ego.station_m,
        ego_curvature_per_m=ego.curvature_per_m,
        vru_x_m=vrus.x_m,
        vru_y_m=vrus.y_m,
        vru_speed_mps=vrus.speed_mps,
    )
    return {name: np.asarray(values) for name, values in first.items()}


def _trim(trace: dict[str, np.ndarray], row: dict) -> dict[str, np.ndarray]:
    """Drop the samples after the variant stopped (a batch runs until its last variant stops)."""
    end_s = row["end_time_s"]
    if end_s is None:
        return trace
    keep = trace["t_s"] <= end_s + 1e-9
    return {name: values[keep] for name, values in trace.items()}


def key_events(row: dict, trace: dict[str, np.ndarray]) -> dict[str, float]:
    """Times (s) of first perception (sensor or V2X), brake onset, and impact or else closest approach."""
    events: dict[str, float] = {}
    seen = [t for t in (row["first_sensor_detection_s"], row["first_v2x_message_s"]) if t is not None]
    if seen:
        events["first_perception"] = min(seen)
    braking = np.flatnonzero(trace["ego_command_mps2"][1:] < -1e-9)
    if braking.size:
        events["brake_onset"] = round(float(trace["t_s"][braking[0]]), 6)
    if row["collided"]:
        events["impact"] = float(row["contact_time_s"])
    else:
        events["closest_approach"] = float(trace["t_s"][int(np.argmin(trace["clearance_m"]))])
    return events

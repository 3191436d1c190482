"""Probe runs of the VUT alone: when does it reach a station along its route, with the engine's own dynamics.

The low-speed tests (ncap/build_low_speed.py) time their targets from such runs (driver request, actuator lag,
jerk limit). A probe is keyed by the ego's dynamics and a duration in whole steps; probes of the same key are run
once. `batched_probes` runs every probe a set of builds asks for in one batch: the builds run first in a
collecting mode that records the probes they need (a build that needs one stops there), then all of them run
together and the builds run again. A variant's run is bit-identical alone and in a batch, so the results equal
one run per probe.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

from vrusim.engine.simulate import check_budgets
from vrusim.engine.stepper import BatchStepper
from vrusim.planners.base import HoldSpeedPlanner
from vrusim.scenario.schema import Scenario
from vrusim.sim.params import pack

DT_S = 0.01
"""Simulation step of a probe, s (the tests' step)."""
PROBE_ROUTE_M = 500.0
"""Route of a probe run, m: far more than a low-speed VUT covers in the probe's seconds."""

Key = tuple[str, float]
"""(dynamics as sorted JSON, duration s) of a probe."""
_RUNS: dict[Key, tuple[np.ndarray, np.ndarray]] = {}
"""(time s, route station m) per probe run so far."""
_MAX_RUNS = 256
_collecting: set[Key] | None = None


class ProbeNeeded(Exception):  # noqa: N818 (a signal, not an error)
    """Raised in collecting mode by a build that needs a probe not yet run."""


def travel_probe_s(ego: dict, travel_m: float, duration_s: float) -> float:
    """Time until the ego (its driver, planner `none`) has travelled `travel_m`, s, from a probe run of the ego
    alone, interpolated between steps. Probes of the same dynamics share one run (the start pose and route
    do not change the travel along the route)."""
    dynamics = {key: value for key, value in ego.items() if key not in ("start", "route")}
    t, station = _probe((json.dumps(dynamics, sort_keys=True), round(duration_s, 2)))
    k = int(np.argmax(station >= travel_m))
    if station[k] < travel_m or k == 0:
        raise ValueError(f"the probe does not travel {travel_m:g} m in {duration_s:g} s")
    return float(t[k - 1] + (travel_m - station[k - 1]) / (station[k] - station[k - 1]) * (t[k] - t[k - 1]))


def _probe(key: Key) -> tuple[np.ndarray, np.ndarray]:
    """The run of probe `key`: from earlier runs, else run now (or, collecting, recorded and ProbeNeeded)."""
    run = _RUNS.get(key)
    if run is not None:
        return run
    if _collecting is not None:
        _collecting.add(key)
        raise ProbeNeeded
    _run([key])
    return _RUNS[key]


def _scenario(key: Key) -> Scenario:
    """The ego with these dynamics driving alone from rest on a straight route that never ends in time."""
    dynamics_json, duration_s = key
    ego = {**json.loads(dynamics_json), "start": {"x_m": 0.0, "y_m": 0.0, "heading_deg": 0.0}}
    ego["route"] = {"kind": "straight", "length_m": PROBE_ROUTE_M}
    far = {"type": "pedestrian", "start": {"x_m": 1e4, "y_m": 1e4}, "heading_deg": 0.0, "top_speed_mps": 0.0}
    mapping = {"name": "probe", "ego": ego, "planner": {"name": "none"}, "vrus": [far],
               "sim": {"dt_s": DT_S, "duration_s": duration_s}}  # fmt: skip
    return Scenario.model_validate(mapping)


def _run(keys: list[Key]) -> None:
    """Run the probes `keys` as one batch; each keeps the rows of its own duration."""
    if len(_RUNS) + len(keys) > _MAX_RUNS:
        _RUNS.clear()
    t_s, station_m = _stations([_scenario(key) for key in keys])
    for index, key in enumerate(keys):
        rows = math.ceil(key[1] / DT_S - 1e-9) + 1  # the steps of its own duration, and t = 0
        _RUNS[key] = (t_s[:rows].copy(), station_m[:rows, index].copy())


def _stations(scenarios: list[Scenario]) -> tuple[np.ndarray, np.ndarray]:
    """Time (s) and each ego's route station (m) after every step of a batch of probes, as the trace of
    `simulate(scenarios, trace=True)` has them (`t_s`, `ego_station_m`): the engine's own steps under the `none`
    planner (its driver's request), every variant to the batch's last step, without the rest of a trace and the
    streamed metrics (a probe needs neither)."""
    batch = pack(scenarios)
    check_budgets(batch, trace=False)
    planner = HoldSpeedPlanner()
    planner.reset(batch)
    stepper = BatchStepper(batch, len(planner.mode_names))
    t_s, station_m = [], []
    for _ in range(batch.n_steps):
        running = stepper.advance(planner.act(stepper.observe())).running
        t_s.append(stepper.t_s)
        station_m.append(stepper.ego.station_m.copy())
        if running == 0:
            break
    return np.array(t_s), np.array(station_m)


@contextmanager
def _collect() -> Iterator[set[Key]]:
    global _collecting
    _collecting = set()
    try:
        yield _collecting
    finally:
        _collecting = None


def batched_probes(builds: list[Callable[[], object]]) -> None:
    """Run every probe the `builds` need, in as few batches as they need probes one after the other."""
    pending = list(builds)
    while pending:
        with _collect() as needed:
            waiting = []
            for build in pending:
                try:
                    build()
                except ProbeNeeded:
                    waiting.append(build)
        if not needed:
            return
        _run(sorted(needed))
        pending = waiting

"""Metrics declared outside vrusim, as a plug-in declares them: one module, registered, nothing edited in core.

`register()` adds them to the catalogue (`vrusim.metrics.catalog`); `unregister()` removes them again.
"""

from __future__ import annotations

import numpy as np

from vrusim.metrics.catalog import BatchView, Metric, register_metric, unregister_metric


def _mean_speed(view: BatchView) -> np.ndarray:
    """Distance along the route over the active time (the ego starts at station 0)."""
    m = view.accumulators
    return m.final_station_m / np.maximum(m.elapsed_s, view.params.dt_s)


def _stopped(view: BatchView) -> np.ndarray:
    return view["final_speed_mps"] == 0.0


MEAN_SPEED = Metric(
    "mean_speed_mps",
    "m/s",
    "Mean speed",
    "final rear-axle station / active time",
    _mean_speed,
    reduce="derived",
    source="tests/extra_metric.py",
)
STOPPED = Metric(
    "stopped_at_end",
    "",
    "Stopped at the end",
    "the ego stands still at the end of the run",
    _stopped,
    dtype="bool",
    source="tests/extra_metric.py",
)
METRICS = (MEAN_SPEED, STOPPED)


def register() -> None:
    for metric in METRICS:
        register_metric(metric)


def unregister() -> None:
    for metric in METRICS:
        unregister_metric(metric.name)

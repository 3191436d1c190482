"""Per-variant results of a batch run as columns (NumPy arrays), for tables, Parquet files and summaries.

The columns are those of the metric catalogue (`vrusim.metrics.catalog`), in table order: the outcome
columns, the measures, the planner's mode entry times and transition count, then the scores; a metric that is
several columns (`first_mode_s`) gives one per planner mode but the first (`first_<mode>_s`).

Float columns hold NaN where a value is absent (no collision, never detected, ...); writers turn NaN into
a missing value (JSON null, Parquet NULL), so no NaN ever reaches a results file.
"""

from __future__ import annotations

import numpy as np

from vrusim.engine.simulate import BatchRun
from vrusim.metrics.catalog import BatchView, groups, metrics

__all__ = ["FLOAT_COLUMNS", "SCORE_COLUMNS", "columns_of", "result_columns", "score_arrays"]

FLOAT_COLUMNS = tuple(m.name for m in metrics() if m.group == "measure" and m.dtype == "float64" and m.split is None)
"""The built-in float measure columns of one column each, in table order (NaN: absent); a per-VRU metric
(`min_ttc_per_vru_s`) has one column per VRU slot."""
SCORE_COLUMNS = tuple(m.name for m in metrics() if m.group == "score")
"""The built-in score columns."""
_SCORE_INPUTS = ("rms_accel_mps2", "rms_jerk_mps3", "free_travel_time_s", "trip_time_s")


def score_arrays(run: BatchRun) -> dict[str, np.ndarray]:
    """Scores and the derived quantities they use, per variant."""
    view = BatchView(run)
    return {name: view[name] for name in (*_SCORE_INPUTS, *SCORE_COLUMNS)}


def columns_of(view: BatchView) -> dict[str, np.ndarray]:
    """Every metric's columns for the batch of `view`, in table order."""
    columns: dict[str, np.ndarray] = {}
    for _, members in groups():
        for metric in members:
            columns.update(metric.columns(view))
    return columns


def result_columns(run: BatchRun) -> dict[str, np.ndarray]:
    """Outcome, impact, event times, metrics and scores per variant ([B] arrays; NaN: absent)."""
    return columns_of(BatchView(run))

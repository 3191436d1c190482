"""One summary row per variant: what ran, then every metric of the catalogue in catalogue order (outcome, event
times, metrics, scores), then the score profile; absent values are None, never NaN."""

from __future__ import annotations

from vrusim.engine.simulate import BatchRun
from vrusim.metrics.catalog import BatchView, metrics, score_profile_names
from vrusim.metrics.columns import columns_of, score_arrays

__all__ = ["score_arrays", "summary_rows"]


def summary_rows(run: BatchRun) -> list[dict]:
    """A JSON-ready dict per variant."""
    view = BatchView(run)
    columns = columns_of(view)
    values = {metric.name: metric.json_values(view, columns) for metric in metrics()}
    profiles = score_profile_names(view)
    rows = []
    params = run.params
    for b in range(params.size):
        row = {"scenario": params.names[b], "v2x": bool(params.v2x_enabled[b]), "planner": params.planner_names[b]}
        row.update({name: per_variant[b] for name, per_variant in values.items()})
        row["score_profile"] = profiles[b]
        rows.append(row)
    return rows

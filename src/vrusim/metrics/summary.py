"""One summary row per variant: outcome, event times, metrics and scores; absent values are None, never NaN."""

from __future__ import annotations

import math

from vrusim.engine.simulate import BatchRun
from vrusim.metrics.columns import FLOAT_COLUMNS, result_columns, score_arrays

__all__ = ["score_arrays", "summary_rows"]

_EVENTS_BEFORE_MODES = FLOAT_COLUMNS[: FLOAT_COLUMNS.index("min_clearance_m")]
_METRICS_AFTER_MODES = FLOAT_COLUMNS[FLOAT_COLUMNS.index("min_clearance_m") :]


def _value(x) -> float | None:
    x = float(x)
    return None if math.isnan(x) or math.isinf(x) else round(x, 6)


def summary_rows(run: BatchRun) -> list[dict]:
    """A JSON-ready dict per variant."""
    p = run.params
    columns = result_columns(run)
    per_variant: dict[int, list[dict]] = {}
    for t, v, a, c in run.metrics.transitions:
        per_variant.setdefault(v, []).append({"t_s": round(t, 6), "from": run.mode_names[a], "to": run.mode_names[c]})
    modes = [name for index, name in enumerate(run.mode_names) if index > 0]
    rows = []
    for b, scenario in enumerate(p.scenarios):
        collided = bool(columns["collided"][b])
        row = {
            "scenario": scenario.name,
            "v2x": bool(scenario.v2x.enabled),
            "planner": scenario.planner.name,
            "outcome": columns["outcome"][b],
            "collided": collided,
        }
        row.update({name: _value(columns[name][b]) for name in _EVENTS_BEFORE_MODES[:6]})
        row["impact_side"] = columns["impact_side"][b]
        row["impact_lateral_fraction"] = _value(columns["impact_lateral_fraction"][b])
        row["impact_vru"] = int(columns["impact_vru"][b]) if collided else None
        row.update({name: _value(columns[name][b]) for name in _EVENTS_BEFORE_MODES[7:]})
        row["first_mode_s"] = {name: _value(columns[f"first_{name}_s"][b]) for name in modes}
        row["transitions"] = per_variant.get(b, [])
        row.update({name: _value(columns[name][b]) for name in _METRICS_AFTER_MODES})
        row.update({name: round(float(columns[name][b]), 4) for name in ("safety", "efficiency", "comfort")})
        row["score_profile"] = scenario.metrics.profile
        rows.append(row)
    return rows

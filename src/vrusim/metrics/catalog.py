"""Every per-variant result of a run, each declared once: the metric catalogue.

A `Metric` states its name (the result column and the JSON key; the unit is the name's suffix), unit, label,
definition and the section of docs/metrics.md that derives it, its column dtype, how the step loop reduces it
and how a batch computes it (`compute(view)`, one value per variant). Everything else is derived from the
catalogue, in catalogue order: the result columns (`metrics.columns`), the JSON summary rows
(`metrics.summary`), the sweep's Arrow schema (`sweep.tables`), the terminal summary (`metrics.display`) and the
HTML report's summary table (`report.parts`).

The streaming accumulators are engine state, one layer below: the engine declares its rows and their
reductions (`engine.accumulators.ACCUMULATORS`) and knows nothing of metrics; a metric that is an accumulator
row names it (`from_accumulator`), which also gives the metric its reduction. A metric computed from
accumulators and packed parameters (an RMS, a trip time, a score) is declared here alone; so is a plug-in's,
through `register_metric` (docs/metrics.md, "The catalogue").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from vrusim.engine.accumulators import ACCUMULATORS, REDUCTIONS
from vrusim.geometry.contact import (
    IMPACT_SIDE_NAMES,
    body_side,
    impact_location,
    impact_side,
    lateral_impact_fraction,
)
from vrusim.metrics import surrogates as sm
from vrusim.metrics.outcome import outcomes
from vrusim.metrics.scores import profile, scores

if TYPE_CHECKING:
    from vrusim.engine.simulate import BatchRun

__all__ = [
    "DTYPES",
    "GROUPS",
    "IDENTITY_KEYS",
    "METRIC_REDUCTIONS",
    "BatchView",
    "Metric",
    "column_dtype",
    "from_accumulator",
    "get_metric",
    "groups",
    "is_builtin",
    "metrics",
    "register_metric",
    "score_profile_names",
    "unregister_metric",
]

GROUPS = ("outcome", "measure", "planner", "score")
"""Where a metric's columns go in a results table: outcome columns first, then measures, the planner's mode
times and transition count, and the scores (the JSON row keeps catalogue order)."""
DTYPES = ("float64", "int64", "bool", "string")
"""Column dtypes (Arrow type aliases). float64 columns hold NaN where a value is absent."""
METRIC_REDUCTIONS = {
    **{name: text for name, text in REDUCTIONS.items() if name != "carry"},
    "any": "true once it happened in an active step",
    "count": "number of events over the active steps",
    "rms": "root mean square over the moving time: sqrt(sum of value^2 dt / moving time)",
    "derived": "computed after the run from other metrics and the scenario's parameters",
}
"""How a metric is reduced over a run: the accumulators' reductions (`engine.accumulators.REDUCTIONS`) and these."""
IDENTITY_KEYS = ("scenario", "v2x", "planner", "score_profile")
"""Keys of a summary row that name what ran, not a metric (no metric may take these names)."""

Compute = Callable[["BatchView"], np.ndarray]


@dataclass(frozen=True)
class Metric:
    """One per-variant result, declared once (see the module docstring)."""

    name: str
    """Result column and JSON key, snake_case with the unit as suffix (`min_ttc_s`)."""
    unit: str
    """Unit as printed ("s", "m/s", "m/s²"); "" for a pure number (a score, a fraction, an index)."""
    label: str
    """Human name, as in reports ("Min TTC")."""
    doc: str
    """Definition (the formula in words or symbols)."""
    compute: Compute
    """Values of a batch: a [B] array (a planner metric may return [B, modes]; see `split`)."""
    reduce: str = "derived"
    """How the run reduces it: a key of `METRIC_REDUCTIONS`."""
    dtype: str = "float64"
    """Column dtype, one of `DTYPES`."""
    group: str = "measure"
    """Table position, one of `GROUPS`."""
    digits: int | None = 6
    """Decimals kept in the JSON row (floats; an absent or infinite value is null); None: a whole number."""
    short: str = ""
    """Label where space is short (the terminal summary); default: `label`."""
    source: str = "docs/metrics.md"
    """Where the formula is derived and its sources cited (a section of docs/metrics.md)."""
    accumulator: str = ""
    """The engine's accumulator row it is, as is (`from_accumulator`); "" for a metric computed from several."""
    split: Callable[[BatchView, np.ndarray], dict[str, np.ndarray]] | None = field(default=None, repr=False)
    """For a metric that is several columns (one per planner mode): its columns from the computed values."""
    to_json: Callable[[BatchView, dict[str, np.ndarray]], list] | None = field(default=None, repr=False)
    """For a metric whose JSON value is not its column's value: the value of each variant (view, columns)."""

    def columns(self, view: BatchView) -> dict[str, np.ndarray]:
        """The result columns of this metric for a batch (float64 columns: NaN where absent or not finite)."""
        values = view[self.name]
        out = self.split(view, values) if self.split is not None else {self.name: values}
        for name, column in out.items():
            if np.shape(column) != (view.size,):
                raise ValueError(f"metric {self.name}: column {name} has shape {np.shape(column)}, not ({view.size},)")
            if self.dtype == "float64":
                column = np.asarray(column, dtype=float)
                out[name] = np.where(np.isfinite(column), column, np.nan)
        return out

    def json_values(self, view: BatchView, columns: dict[str, np.ndarray]) -> list:
        """The JSON value of each variant (never NaN: an absent value is None), from the batch's `columns`."""
        if self.to_json is not None:
            return self.to_json(view, columns)
        values = columns[self.name].tolist()
        if self.dtype == "float64":
            return [_number(x, self.digits) for x in values]
        if self.dtype == "bool":
            return [bool(x) for x in values]
        if self.dtype == "int64":
            return [int(x) for x in values]
        return [None if x is None else str(x) for x in values]


def _number(value: float, digits: int | None) -> float | int | None:
    x = float(value)
    if not math.isfinite(x):
        return None
    return int(x) if digits is None else round(x, digits)


class BatchView:
    """What a metric reads of one batch run: `view.run`, `view.params`, `view.accumulators` (the engine's
    `RunMetrics`, one attribute per accumulator row), and `view[name]`, another metric's values (computed once
    per view, as `compute` returns them: not yet filtered for absent values)."""

    def __init__(self, run: BatchRun):
        self.run = run
        self.params = run.params
        self.accumulators = run.metrics
        self.size = run.params.size
        self._values: dict[str, np.ndarray] = {}
        self._shared: dict[str, Any] = {}

    def __getitem__(self, name: str) -> np.ndarray:
        values = self._values.get(name)
        if values is None:
            values = self._values[name] = get_metric(name).compute(self)
        return values

    def shared(self, key: str, make: Callable[[BatchView], Any]) -> Any:
        """A value several metrics compute together (the three scores), made once per view."""
        if key not in self._shared:
            self._shared[key] = make(self)
        return self._shared[key]


# ----------------------------------------------------------------------------------------------- registry

_METRICS: dict[str, Metric] = {}
"""The catalogue, in catalogue order."""
_ACCUMULATOR_REDUCE = {row.name: row.reduce for row in ACCUMULATORS}


def metrics() -> tuple[Metric, ...]:
    """Every metric, in catalogue order (the JSON row's order)."""
    return tuple(_METRICS.values())


def get_metric(name: str) -> Metric:
    """The metric of that name; KeyError naming the known ones otherwise."""
    try:
        return _METRICS[name]
    except KeyError:
        raise KeyError(f"no metric {name!r}; known: {', '.join(_METRICS)}") from None


def _check(metric: Metric) -> None:
    if not metric.name.isidentifier() or metric.name != metric.name.lower():
        raise ValueError(f"metric name {metric.name!r}: expected a snake_case identifier")
    if metric.name in _METRICS:
        raise ValueError(f"metric {metric.name!r} is already declared")
    if metric.name in IDENTITY_KEYS:
        raise ValueError(f"metric name {metric.name!r}: a summary row's key for what ran ({', '.join(IDENTITY_KEYS)})")
    for attribute, allowed in (("dtype", DTYPES), ("group", GROUPS), ("reduce", tuple(METRIC_REDUCTIONS))):
        if getattr(metric, attribute) not in allowed:
            raise ValueError(f"metric {metric.name}: {attribute} {getattr(metric, attribute)!r} not in {allowed}")
    if not metric.label:
        raise ValueError(f"metric {metric.name}: a label is required")


def register_metric(metric: Metric, *, after: str | None = None) -> Metric:
    """Add a metric to the catalogue (at the end, or right after the metric `after`); returns it.

    From then on it is a result column, a key of every summary row, a sweep Parquet column and a line of the
    terminal summary. `unregister_metric` removes it again.
    """
    _check(metric)
    if after is None:
        _METRICS[metric.name] = metric
        return metric
    get_metric(after)
    items = list(_METRICS.items())
    at = [name for name, _ in items].index(after) + 1
    items.insert(at, (metric.name, metric))
    _METRICS.clear()
    _METRICS.update(items)
    return metric


def unregister_metric(name: str) -> Metric:
    """Remove a metric registered with `register_metric` (built-in metrics stay); returns it."""
    if name in _BUILTIN:
        raise ValueError(f"metric {name!r} is built in and cannot be removed")
    metric = get_metric(name)
    del _METRICS[name]
    return metric


def is_builtin(name: str) -> bool:
    """Whether the metric is one of vrusim's own (not registered by a plug-in)."""
    return name in _BUILTIN


def column_dtype(column: str) -> str:
    """Dtype of a result column: its metric's; a column a metric splits into (`first_<mode>_s`) is float64."""
    metric = _METRICS.get(column)
    return metric.dtype if metric is not None else "float64"


def groups() -> Iterator[tuple[str, tuple[Metric, ...]]]:
    """The metrics of each group, in table order."""
    for group in GROUPS:
        yield group, tuple(m for m in _METRICS.values() if m.group == group)


# ----------------------------------------------------------------------------------------------- declarations


def from_accumulator(
    name: str, unit: str, label: str, doc: str, row: str | None = None, source: str = "docs/metrics.md", **kwargs
) -> Metric:
    """A metric that is the engine's accumulator `row` (default: `name`) as is; its reduction is the row's."""
    row = row or name
    if row not in _ACCUMULATOR_REDUCE:
        raise KeyError(f"metric {name}: no accumulator row {row!r} in vrusim.engine.accumulators.ACCUMULATORS")

    def compute(view: BatchView) -> np.ndarray:
        return getattr(view.accumulators, row)

    reduce = _ACCUMULATOR_REDUCE[row]
    return Metric(name, unit, label, doc, compute, reduce=reduce, source=source, accumulator=row, **kwargs)


def _collided(view: BatchView) -> np.ndarray:
    return view.accumulators.collided.copy()


def _outcome(view: BatchView) -> np.ndarray:
    m, p = view.accumulators, view.params
    return outcomes(view["collided"], ~np.isnan(m.travel_time_s), p.cruise_speed_mps, m.final_speed_mps)


def _impact_side(view: BatchView) -> np.ndarray:
    m, p = view.accumulators, view.params
    side = impact_side(m.impact_local_x_m, m.impact_local_y_m, p.half_length_m, p.half_width_m)
    names = np.array(IMPACT_SIDE_NAMES, dtype=object)
    return np.where(view["collided"], names[np.clip(side, 0, len(names) - 1)], None)


def _body_side_codes(view: BatchView) -> np.ndarray:
    m, p = view.accumulators, view.params
    side = impact_side(m.impact_local_x_m, m.impact_local_y_m, p.half_length_m, p.half_width_m)
    return body_side(np.clip(side, 0, len(IMPACT_SIDE_NAMES) - 1), p.reverse)


def _impact_body_side(view: BatchView) -> np.ndarray:
    names = np.array(IMPACT_SIDE_NAMES, dtype=object)
    return np.where(view["collided"], names[_body_side_codes(view)], None)


def _impact_location(view: BatchView) -> np.ndarray:
    m, p = view.accumulators, view.params
    location = impact_location(
        _body_side_codes(view), m.impact_vru_local_x_m, m.impact_vru_local_y_m, p.half_length_m, p.half_width_m,
        p.reverse,
    )  # fmt: skip
    return np.where(view["collided"], location, np.nan)


def _door_collision(view: BatchView) -> np.ndarray:
    return view["collided"] & (view.accumulators.impact_door > 0.5)


def _lateral_fraction(view: BatchView) -> np.ndarray:
    fraction = lateral_impact_fraction(view.accumulators.impact_local_y_m, view.params.half_width_m)
    return np.where(view["collided"], fraction, np.nan)


def _impact_vru(view: BatchView) -> np.ndarray:
    return np.where(view["collided"], view.accumulators.impact_vru, np.nan)


def _first_modes(view: BatchView) -> np.ndarray:
    return view.accumulators.first_mode_s[:, 1:]


def _mode_columns(view: BatchView, values: np.ndarray) -> dict[str, np.ndarray]:
    return {f"first_{mode}_s": values[:, i] for i, mode in enumerate(view.run.mode_names[1:])}


def _first_modes_json(view: BatchView, columns: dict[str, np.ndarray]) -> list[dict[str, float | None]]:
    modes = view.run.mode_names[1:]
    per_mode = {mode: [_number(x, 6) for x in columns[f"first_{mode}_s"].tolist()] for mode in modes}
    return [{mode: values[b] for mode, values in per_mode.items()} for b in range(view.size)]


def _transition_count(view: BatchView) -> np.ndarray:
    variants = [v for _, v, _, _ in view.accumulators.transitions]
    return np.bincount(variants, minlength=view.size).astype(np.int64)


def _transitions_json(view: BatchView, columns: dict[str, np.ndarray]) -> list[list[dict]]:
    names = view.run.mode_names
    per_variant: list[list[dict]] = [[] for _ in range(view.size)]
    for t, v, a, c in view.accumulators.transitions:
        per_variant[v].append({"t_s": round(t, 6), "from": names[a], "to": names[c]})
    return per_variant


def _rms(sum_row: str) -> Compute:
    # over the moving time, not the active time: standing still must not dilute the RMS (docs/metrics.md)
    def compute(view: BatchView) -> np.ndarray:
        moving = np.maximum(view.accumulators.moving_s, view.params.dt_s)
        return np.sqrt(getattr(view.accumulators, sum_row) / moving)

    return compute


def _free_travel_time(view: BatchView) -> np.ndarray:
    p = view.params
    with np.errstate(divide="ignore"):
        return np.where(p.cruise_speed_mps > 0, p.route_length_m / p.cruise_speed_mps, 0.0)


def _trip_time(view: BatchView) -> np.ndarray:
    m, p = view.accumulators, view.params
    # a trip not completed when the run ended is finished in thought at cruise speed (docs/metrics.md)
    station = np.minimum(p.route_length_m, m.final_station_m)
    remaining = np.where(
        p.cruise_speed_mps > 0, (p.route_length_m - station) / np.maximum(p.cruise_speed_mps, 1e-9), 0.0
    )
    travel = np.where(np.isnan(m.travel_time_s), m.end_time_s + remaining, m.travel_time_s)
    travel = np.where(view["outcome"] == "stalled", np.inf, travel)  # a stalled ego never finishes: no trip time
    return np.where(p.cruise_speed_mps > 0, travel, 0.0)  # an ego told to stand still loses no time


def score_profile_names(view: BatchView) -> list[str]:
    """The score profile of each variant (its scenario's `metrics.profile`)."""
    return list(view.params.score_profiles)


def _scores(view: BatchView) -> dict[str, np.ndarray]:
    per_profile: dict[tuple, list[int]] = {}
    for b, name in enumerate(score_profile_names(view)):
        overrides = tuple(sorted(view.params.score_overrides[b].items()))
        per_profile.setdefault((name, overrides), []).append(b)
    out = {name: np.zeros(view.size) for name in ("safety", "efficiency", "comfort")}
    inputs = ("collided", "min_ttc_s", "trip_time_s", "free_travel_time_s", "rms_accel_mps2", "rms_jerk_mps3")
    stalled, clearance = view["outcome"] == "stalled", view["min_clearance_m"]
    for (name, overrides), members in per_profile.items():
        idx = np.array(members)
        extra = {"min_clearance_m": clearance[idx], "stalled": stalled[idx]}
        result = scores(*(view[i][idx] for i in inputs), replace(profile(name), **dict(overrides)), **extra)
        for score, values in out.items():
            values[idx] = result[score]
    return out


def _score(name: str) -> Compute:
    def compute(view: BatchView) -> np.ndarray:
        return view.shared("scores", _scores)[name]

    return compute


CONTACT = "docs/metrics.md#contact"
TTC = "docs/metrics.md#time-to-collision-2-d-geometryttcpy"
DYNAMICS = "docs/metrics.md#longitudinal-and-lateral-dynamics"
TRAVEL = "docs/metrics.md#travel-time-and-trip-time"
EVENTS = "docs/metrics.md#events"
SCORES = "docs/metrics.md#scores-metricsscorespy"
OUTCOME = "docs/metrics.md#outcome"

_BUILTIN_METRICS = (
    Metric("outcome", "", "Outcome", '"collision", "avoided", "stalled" or "incomplete"', _outcome, dtype="string",
           group="outcome", source=OUTCOME),
    Metric("collided", "", "Collided", "the bodies touched in an active step", _collided, reduce="any",
           dtype="bool", group="outcome", source=CONTACT),
    from_accumulator("contact_time_s", "s", "Contact time", "t + f dt, f where the bodies met inside the step",
                     source=CONTACT),
    from_accumulator("impact_ego_speed_mps", "m/s", "Impact ego speed", "v0 + f (v1 - v0) at the contact",
                     source=CONTACT),
    from_accumulator("impact_relative_speed_mps", "m/s", "Impact relative speed", "|v_ego h - v_vru|",
                     source=CONTACT),
    from_accumulator("impact_relative_longitudinal_speed_mps", "m/s", "Impact relative longitudinal speed",
                     "(v_ego h - v_vru) . h", row="impact_relative_longitudinal_mps", source=CONTACT),
    from_accumulator("impact_point_x_m", "m", "Impact point x", "outline point closest to the VRU, vehicle frame",
                     row="impact_local_x_m", source=CONTACT),
    from_accumulator("impact_point_y_m", "m", "Impact point y", "outline point closest to the VRU, vehicle frame",
                     row="impact_local_y_m", source=CONTACT),
    Metric("impact_side", "", "Impact side", "front, rear, left or right: the edge of the impact point",
           _impact_side, reduce="at", dtype="string", group="outcome", source=CONTACT),
    Metric("impact_lateral_fraction", "", "Impact lateral fraction", "clip((y + w) / 2w, 0, 1): 0 right, 1 left",
           _lateral_fraction, reduce="at", source=CONTACT),
    Metric("impact_body_side", "", "Impact side of the body",
           "impact_side on the real body: front and rear, left and right swapped for a reversing ego",
           _impact_body_side, reduce="at", dtype="string", group="outcome", source=CONTACT),
    Metric("impact_location", "", "Impact location",
           "VRU centre at contact: front/rear (y + w) / 2w (0 right), sides (x + l) / 2l (0 rear); LSC26 §1.2.2",
           _impact_location, reduce="at", source=CONTACT),
    Metric("door_collision", "", "Door collision", "the first contact was with the opened door (ego.door)",
           _door_collision, reduce="at", dtype="bool", group="outcome", source=CONTACT),
    Metric("impact_vru", "", "Impact VRU slot", "index of the VRU hit in the scenario's list", _impact_vru,
           reduce="at", group="outcome", digits=None, source=CONTACT),
    from_accumulator("first_sensor_detection_s", "s", "First sensor detection", "any VRU perceived by the sensor",
                     row="first_sensor_s", source=EVENTS),
    from_accumulator("first_v2x_message_s", "s", "First V2X message", "any VRU's message received",
                     row="first_v2x_s", source=EVENTS),
    from_accumulator("first_warning_s", "s", "First warning", "forward-collision warning issued", source=EVENTS),
    from_accumulator("warning_ttc_s", "s", "TTC at warning", "min TTC of the state the warning was issued on",
                     source=EVENTS),
    Metric("first_mode_s", "s", "First entry per planner mode", "first entry time of each mode but the first",
           _first_modes, reduce="first", group="planner", source=EVENTS, split=_mode_columns,
           to_json=_first_modes_json),
    Metric("transitions", "", "Planner transitions", "every mode change {t_s, from, to}; the column counts them",
           _transition_count, reduce="count", dtype="int64", group="planner", source=EVENTS,
           to_json=_transitions_json),
    from_accumulator("min_clearance_m", "m", "Min clearance", "smallest clearance, < 0 when penetrating",
                     source=CONTACT),
    from_accumulator("min_ttc_s", "s", "Min TTC", "smallest 2-D TTC over VRUs and steps", source=TTC),
    from_accumulator("peak_accel_mps2", "m/s²", "Peak acceleration", "max a_k", source=DYNAMICS),
    from_accumulator("peak_decel_mps2", "m/s²", "Peak deceleration", "max -a_k", source=DYNAMICS),
    from_accumulator("peak_jerk_mps3", "m/s³", "Peak jerk", "max |j_k|", source=DYNAMICS),
    from_accumulator("peak_lateral_accel_mps2", "m/s²", "Peak lateral acceleration", "max v_k² |κ_k|",
                     source=DYNAMICS),
    Metric("rms_accel_mps2", "m/s²", "RMS acceleration", "sqrt(Σ a_k² dt / T_moving)", _rms("sum_accel_sq"),
           reduce="rms", short="RMS accel", source=DYNAMICS),
    Metric("rms_jerk_mps3", "m/s³", "RMS jerk", "sqrt(Σ j_k² dt / T_moving)", _rms("sum_jerk_sq"), reduce="rms",
           source=DYNAMICS),
    from_accumulator("moving_time_s", "s", "Moving time", "Σ dt over the active steps in which the ego moved",
                     row="moving_s", source=DYNAMICS),
    from_accumulator("travel_time_s", "s", "Travel time", "the route completed, interpolated in the step",
                     source=TRAVEL),
    Metric("trip_time_s", "s", "Trip time (scored)", "travel time, or the rest of the route at cruise speed",
           _trip_time, source=TRAVEL),
    Metric("free_travel_time_s", "s", "Free-flow travel time", "route length / cruise speed", _free_travel_time,
           source=TRAVEL),
    from_accumulator("end_time_s", "s", "End time", "time of the last active step's end", source=TRAVEL),
    from_accumulator("final_speed_mps", "m/s", "Final speed", "ego speed at end_time_s", source=TRAVEL),
    Metric("safety", "", "Safety score",
           "min(1, TTC_min / ttc_threshold_s, clearance_min / clearance_threshold_m); 0 on collision",
           _score("safety"), group="score", digits=4, source=SCORES),
    Metric("efficiency", "", "Efficiency score", "1 / (1 + (loss / loss_scale)^loss_exponent); 0 on collision or stall",
           _score("efficiency"), group="score", digits=4, source=SCORES),
    Metric("comfort", "", "Comfort score", "exp(-(a_rms / accel_scale)² - (j_rms / jerk_scale)²); 0 on collision",
           _score("comfort"), group="score", digits=4, source=SCORES),
)  # fmt: skip

SEVERITY = "docs/metrics.md#collision-severity"
INJURY = "docs/metrics.md#injury-risk-metricsinjury_riskpy"
SURROGATE = "docs/metrics.md#surrogate-safety-measures"
PET = "docs/metrics.md#post-encroachment-time"
PER_VRU = "docs/metrics.md#per-vru-minima"

_SAFETY_METRICS = (
    ("impact_vru", Metric("speed_reduction_mps", "m/s", "Speed reduction before impact",
                          "cruise speed - impact ego speed (collisions only)", sm.speed_reduction, reduce="at",
                          source=SEVERITY)),
    ("speed_reduction_mps", Metric("delta_v_ego_mps", "m/s", "Ego Δv", "m_vru / (m_ego + m_vru) |v_rel|; 0: none",
                                   sm.delta_v_ego, reduce="at", source=SEVERITY)),
    ("delta_v_ego_mps", Metric("delta_v_vru_mps", "m/s", "VRU Δv", "m_ego / (m_ego + m_vru) |v_rel|; 0: none",
                               sm.delta_v_vru, reduce="at", source=SEVERITY)),
    ("delta_v_vru_mps", Metric("fatality_risk", "", "Fatality risk",
                               "metrics.injury_risk_curve at the impact relative speed; 0: no collision",
                               sm.fatality_risk, reduce="at", source=INJURY)),
    ("fatality_risk", Metric("serious_injury_risk", "", "Serious injury risk (AIS 4+)",
                             "Tefft (2013) AIS 4+ curve at the impact relative speed; 0: no collision",
                             sm.serious_injury_risk, reduce="at", short="Serious injury risk",
                             source=INJURY)),
    ("min_clearance_m", from_accumulator("min_clearance_time_s", "s", "Time of min clearance",
                                         "time of min_clearance_m", source=CONTACT)),
    ("min_ttc_s", from_accumulator("min_ttc_time_s", "s", "Time of min TTC", "time of min_ttc_s", source=TTC)),
    ("min_ttc_time_s", from_accumulator("min_lateral_clearance_m", "m", "Min lateral clearance while passing",
                                        "min |y| - w - r while the VRU centre is alongside (|x| <= l)",
                                        short="Min lateral clearance", source=SURROGATE)),
    ("min_lateral_clearance_m", from_accumulator("min_lateral_clearance_time_s", "s", "Time of min lateral clearance",
                                                 "time of min_lateral_clearance_m", source=SURROGATE)),
    ("min_lateral_clearance_time_s", from_accumulator("tet_s", "s", "Time exposed TTC (TET)",
                                                      "Σ dt while 0 <= TTC_min <= metrics.tet_ttc_threshold_s",
                                                      short="TET", source=SURROGATE)),
    ("tet_s", from_accumulator("tit_s2", "s²", "Time integrated TTC (TIT)",
                               "Σ (TTC* - TTC_min) dt while 0 <= TTC_min <= TTC*", short="TIT", source=SURROGATE)),
    ("tit_s2", from_accumulator("peak_drac_mps2", "m/s²", "Peak DRAC", "max v_close / (2 TTC)", source=SURROGATE)),
    ("peak_drac_mps2", from_accumulator("peak_drac_time_s", "s", "Time of peak DRAC", "time of peak_drac_mps2",
                                        source=SURROGATE)),
    ("peak_drac_time_s", Metric("peak_btn", "", "Peak brake threat number", "peak DRAC / ego.max_decel_mps2",
                                sm.peak_btn, reduce="max", digits=4, short="Peak BTN", source=SURROGATE)),
    ("peak_btn", Metric("pet_s", "s", "Post-encroachment time", "min over VRUs: 2nd entry - 1st exit of the zone",
                        sm.pet, reduce="min", short="PET", source=PET)),
    ("pet_s", Metric("min_ttc_per_vru_s", "s", "Min TTC per VRU", "min_ttc_s of each VRU slot (min_ttc_vru<k>_s)",
                     sm.per_vru("min_ttc_s"), reduce="min", source=PER_VRU,
                     split=sm.per_vru_columns("min_ttc_vru{k}_s"), to_json=sm.per_vru_json("min_ttc_vru{k}_s"))),
    ("min_ttc_per_vru_s", Metric("min_clearance_per_vru_m", "m", "Min clearance per VRU",
                                 "min_clearance_m of each VRU slot (min_clearance_vru<k>_m)",
                                 sm.per_vru("min_clearance_m"), reduce="min", source=PER_VRU,
                                 split=sm.per_vru_columns("min_clearance_vru{k}_m"),
                                 to_json=sm.per_vru_json("min_clearance_vru{k}_m"))),
)  # fmt: skip
"""Collision severity, injury risk and surrogate safety measures (issue 17): (the metric they follow, metric)."""

for _metric in _BUILTIN_METRICS:
    register_metric(_metric)
for _after, _metric in _SAFETY_METRICS:
    register_metric(_metric, after=_after)
_BUILTIN = frozenset(_METRICS)

"""The terminal summary of one run (`vrusim run`): label and value text per line, from a summary row.

Labels and units come from the metric catalogue (`vrusim.metrics.catalog`). `SECTIONS` chooses the metrics shown
and where several share a line (relative speed with its longitudinal part, impact side with the lateral
fraction, peak acceleration with peak deceleration, travel time with the free-flow and scored trip times); the
metrics a plug-in registers follow in a section of their own. Value texts are Rich console markup (names
escaped); an absent value shows as "—".
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

from vrusim.metrics.catalog import get_metric, is_builtin, metrics

__all__ = ["SECTIONS", "DisplayRow", "display_rows"]

ABSENT = "—"


class DisplayRow(NamedTuple):
    """One line of the terminal summary; `end_section` draws a rule below it."""

    label: str
    text: str
    end_section: bool = False


class Line(NamedTuple):
    """A line showing metric `name` (label from the catalogue unless given) with its own value text."""

    name: str
    text: Callable[[dict[str, Any]], str]
    label: str = ""


def number(value: float | None, unit: str = "", digits: int = 2) -> str:
    """A value with its unit, fixed decimals; "—" when absent."""
    if value is None:
        return ABSENT
    text = f"{value:.{digits}f}"
    return f"{text} {unit}" if unit else text


def _value(row: dict[str, Any], name: str) -> str:
    return number(row[name], get_metric(name).unit)


def _escape(text: str) -> str:
    from rich.markup import escape

    return escape(text)


_OUTCOME_STYLE = {"collision": "[bold red]COLLISION[/]", "avoided": "[bold green]avoided[/]",
                  "stalled": "[bold yellow]stalled[/] (stood still short of the route end)",
                  "incomplete": "[yellow]incomplete[/] (time limit reached while moving)"}  # fmt: skip


def _outcome(row: dict[str, Any]) -> str:
    outcome = row.get("outcome") or ("collision" if row["collided"] else "avoided")
    return _OUTCOME_STYLE.get(outcome, _escape(str(outcome)))


def _relative_speed(row: dict[str, Any]) -> str:
    text = _value(row, "impact_relative_speed_mps")
    if row["impact_relative_longitudinal_speed_mps"] is not None:
        text += f" (longitudinal {_value(row, 'impact_relative_longitudinal_speed_mps')})"
    return text


def _side(row: dict[str, Any]) -> str:
    if row["impact_side"] is None:
        return ABSENT
    return f"{row['impact_side']}, lateral fraction {_value(row, 'impact_lateral_fraction')}"


def _transitions(row: dict[str, Any]) -> str:
    lines = [
        f"{number(item['t_s'], 's')}  {_escape(item['from'])} → {_escape(item['to'])}" for item in row["transitions"]
    ]
    return "\n".join(lines) if lines else "none"


def _peak_accel_decel(row: dict[str, Any]) -> str:
    return f"{number(row['peak_accel_mps2'])} / {number(row['peak_decel_mps2'])} {get_metric('peak_accel_mps2').unit}"


def _travel(row: dict[str, Any]) -> str:
    free = _value(row, "free_travel_time_s")
    if row["travel_time_s"] is not None:
        return f"{_value(row, 'travel_time_s')} (free flow {free})"
    if row.get("outcome") == "stalled":
        return f"route not completed: stalled, never finishes (efficiency 0; free flow {free})"
    return f"route not completed (trip time counted as {_value(row, 'trip_time_s')}, free flow {free})"


def _with_time(name: str, time: str) -> Callable[[dict[str, Any]], str]:
    def text(row: dict[str, Any]) -> str:
        if row[name] is None:
            return ABSENT
        return f"{_value(row, name)} at {_value(row, time)}"

    return text


def _pair(first: str, second: str) -> Callable[[dict[str, Any]], str]:
    def text(row: dict[str, Any]) -> str:
        return f"{_value(row, first)} / {_value(row, second)}"

    return text


def _per_vru(name: str) -> Callable[[dict[str, Any]], str]:
    def text(row: dict[str, Any]) -> str:
        unit = get_metric(name).unit
        return ", ".join(f"#{k} {number(value, unit)}" for k, value in enumerate(row[name] or ())) or ABSENT

    return text


def _drac(row: dict[str, Any]) -> str:
    if row["peak_drac_time_s"] is None:
        return ABSENT
    return f"{_value(row, 'peak_drac_mps2')} (BTN {number(row['peak_btn'])}) at {_value(row, 'peak_drac_time_s')}"


SECTIONS: tuple[tuple[str | Line, ...], ...] = (
    (Line("outcome", _outcome),),
    (
        "contact_time_s",
        "impact_ego_speed_mps",
        Line("impact_relative_speed_mps", _relative_speed),
        Line("impact_side", _side),
    ),
    ("first_sensor_detection_s", "first_v2x_message_s", Line("transitions", _transitions)),
    (
        "min_ttc_s",
        "min_clearance_m",
        Line("peak_accel_mps2", _peak_accel_decel, "Peak accel / decel"),
        "peak_jerk_mps3",
        "rms_accel_mps2",
        "rms_jerk_mps3",
        Line("travel_time_s", _travel),
    ),
    (
        Line("min_lateral_clearance_m", _with_time("min_lateral_clearance_m", "min_lateral_clearance_time_s")),
        Line("pet_s", lambda row: _value(row, "pet_s")),
        Line("peak_drac_mps2", _drac, "Peak DRAC"),
        Line("tet_s", _pair("tet_s", "tit_s2"), "TET / TIT"),
        Line("min_ttc_per_vru_s", _per_vru("min_ttc_per_vru_s")),
        Line("min_clearance_per_vru_m", _per_vru("min_clearance_per_vru_m")),
        "speed_reduction_mps",
        Line("delta_v_ego_mps", _pair("delta_v_ego_mps", "delta_v_vru_mps"), "Δv ego / VRU"),
        Line("fatality_risk", _pair("fatality_risk", "serious_injury_risk"), "Fatality / serious injury risk"),
    ),
    ("safety", "efficiency", "comfort"),
)
"""The built-in lines, by section: a metric name (its value with its unit) or a `Line`."""


def _plugin_text(row: dict[str, Any], name: str) -> str:
    value = row[name]
    if value is None:
        return ABSENT
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return _value(row, name)
    if isinstance(value, int):
        return f"{value} {get_metric(name).unit}".rstrip()
    return _escape(str(value))


def _lines(row: dict[str, Any], section: tuple[str | Line, ...]) -> list[DisplayRow]:
    out = []
    for item in section:
        line = item if isinstance(item, Line) else Line(item, lambda row, name=item: _value(row, name))
        metric = get_metric(line.name)
        out.append(DisplayRow(line.label or metric.short or metric.label, line.text(row)))
    return out


def display_rows(row: dict[str, Any]) -> list[DisplayRow]:
    """The lines of the terminal summary of a summary row (`summary_rows(...)[i]`), with section ends."""
    sections = [_lines(row, section) for section in SECTIONS]
    plugins = [m for m in metrics() if not is_builtin(m.name) and m.name in row]
    if plugins:
        sections.append([DisplayRow(m.short or m.label, _plugin_text(row, m.name)) for m in plugins])
    out: list[DisplayRow] = []
    for index, section in enumerate(sections):
        last = index == len(sections) - 1
        out += [line._replace(end_section=not last and i == len(section) - 1) for i, line in enumerate(section)]
    return out

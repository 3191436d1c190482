"""Report of the paper reproduction: Table II ours vs paper, caption event times, and per case study the charts,
snapshots and time series with V2X off and on (numbers = `vrusim paper --json`)."""

from __future__ import annotations

from typing import Any

from vrusim.metrics.outcome import outcome_of
from vrusim.paper.cases import paper_scenarios, reproduce, scenario_dir
from vrusim.report.html import Column, Html, facts, join, table, tag
from vrusim.report.page import Report, Section
from vrusim.report.parts import parameters
from vrusim.report.player import player
from vrusim.report.run import figures_of
from vrusim.report.run_charts import run_charts
from vrusim.viz.recording import record

SCORES = ("safety", "efficiency", "comfort")


def case_key(case: dict[str, Any]) -> str:
    """Row key of a case in the tables: "pedestrian/off", "motorcyclist/on"."""
    return f"{case['case']}/{'on' if case['v2x'] else 'off'}"


def _outcome(collided: bool) -> str:
    return "collision" if collided else "avoided"


def table_ii(result: dict[str, Any]) -> Html:
    """Outcomes and scores, paper and ours, with the difference; cells outside the tolerance marked."""
    tolerance = result["tolerances"]["score"]
    rows, classes = [], {}
    for case in result["cases"]:
        key, paper, ours = case_key(case), case["paper"], case["ours"]
        values: dict[str, Any] = {
            "title": case["title"],
            "v2x": "on" if case["v2x"] else "off",
            "outcome_paper": _outcome(paper["collision"]),
            "outcome_ours": outcome_of(ours),
        }
        classes[(key, "outcome_ours")] = "good" if case["outcome_matches"] else "bad"
        for name in SCORES:
            values[f"{name}_paper"] = paper[name]
            values[f"{name}_ours"] = ours[name]
            values[f"{name}_diff"] = ours[name] - paper[name]
            within = abs(ours[name] - paper[name]) <= tolerance + 1e-9
            classes[(key, f"{name}_ours")] = "good" if within else "bad"
        values["within"] = case["scores_within_tolerance"]
        rows.append((key, values))
    columns = [Column("v2x", "V2X"), Column("outcome_paper", "Outcome paper"), Column("outcome_ours", "Outcome ours")]
    for name in SCORES:
        title = name.capitalize()
        columns += [
            Column(f"{name}_paper", f"{title} paper", 2),
            Column(f"{name}_ours", f"{title} ours", 2),
            Column(f"{name}_diff", "Δ", 2),
        ]
    columns.append(Column("within", f"All within ±{tolerance:.2f}"))
    caption = f"Table II of the paper against ours; green / red: within / outside ±{tolerance:.2f}."
    return table("table-ii", columns, rows, caption, row_header=Column("title", "Case"), classes=classes)


def events_table(result: dict[str, Any]) -> Html:
    """Event times from the figure captions against ours."""
    tolerance = result["tolerances"]["time_s"]
    titles = {case["case"]: case["title"] for case in result["cases"]}
    rows, classes = [], {}
    for index, event in enumerate(result["events"]):
        key, ours = str(index), event["ours_s"]
        rows.append(
            (
                key,
                {
                    "case": titles.get(event["case"], event["case"]),
                    "v2x": "on" if event["v2x"] else "off",
                    "event": event["event"],
                    "paper_s": event["paper_s"],
                    "ours_s": ours,
                    "diff_s": None if ours is None else ours - event["paper_s"],
                    "within": event["within_tolerance"],
                },
            )
        )
        classes[(key, "ours_s")] = "good" if event["within_tolerance"] else "bad"
    columns = [
        Column("v2x", "V2X"),
        Column("event", "Event"),
        Column("paper_s", "Paper (s)", 2),
        Column("ours_s", "Ours (s)", 2),
        Column("diff_s", "Δ (s)", 2),
        Column("within", f"±{tolerance:g} s"),
    ]
    return table(
        "events",
        columns,
        rows,
        "Event times stated in the paper's figure captions against ours.",
        row_header=Column("case", "Case"),
        classes=classes,
    )


def match_counts(result: dict[str, Any]) -> list[tuple[str, Html]]:
    """Matching outcomes, events and individual scores, as facts with ids (match-outcomes, ...)."""
    from vrusim.paper.cases import BASES
    from vrusim.paper.cases import match_counts as counts

    return [
        (
            f"scores: {BASES[name]}" if name in BASES else name,
            tag("span", f"{ok} / {total}", id=f"match-{name}", data_value=f"[{ok},{total}]"),
        )
        for name, (ok, total) in counts(result).items()
    ]


def paper_report(result: dict[str, Any] | None = None) -> Report:
    """The paper report; `result` is a `reproduce()` document (run here when not given)."""
    result = reproduce() if result is None else result
    runs = paper_scenarios()
    recordings = record([scenario for _, _, scenario in runs])
    case_sections = []
    for index in range(0, len(runs), 2):
        case = runs[index][0]
        pair = recordings[index : index + 2]
        charts = [
            tag("h3", f"V2X {'on' if v2x else 'off'}") + run_charts(rec, f"{case.key}-{'on' if v2x else 'off'}")
            for (_, v2x, _), rec in zip(runs[index : index + 2], pair, strict=True)
        ]
        groups = [f"{case.key}-{'on' if v2x else 'off'}" for _, v2x, _ in runs[index : index + 2]]
        scene = tag("h3", "Scene player, V2X off and on") + player(pair, f"player-{case.key}", chart_group=groups)
        content = join([scene, *charts, *figures_of(pair, case.key, case.title)])
        case_sections.append(Section(f"case-{case.key}", case.title, content))
    files = [(scenario, scenario_dir() / case.file_name, case.title) for case, v2x, scenario in runs if not v2x]
    sections = [
        Section("matches", "Agreement with the paper", facts(match_counts(result), "matches")),
        Section("table-ii-section", "Table II: outcome and scores", table_ii(result)),
        Section("events-section", "Event times", events_table(result)),
        *case_sections,
        Section("parameters", "Parameters", join(parameters(s, f, title) for s, f, title in files)),
    ]
    return Report(
        kind="paper",
        title="vrusim paper reproduction",
        lead="He, Chen, King & Li, CPSI 2025: the three case studies with V2X off and on, against Table II and "
        "the event times in the figure captions.",
        sections=sections,
        results=result,
    )

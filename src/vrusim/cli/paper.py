"""`vrusim paper`: reproduce the paper's three case studies and compare with its Table II and figure captions."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.cells import mark, number, on_off
from vrusim.cli.figures import check_figures_dir, write_paper_figures
from vrusim.cli.options import JsonOption, ReportOption, file_option
from vrusim.cli.output import console, print_json, user_errors
from vrusim.cli.report import check_report_option, write_report_option

SCORES = ("safety", "efficiency", "comfort")


def _difference(ours: float, paper: float) -> float:
    """ours - paper rounded for display (never "-0.00")."""
    return round(ours - paper, 2) + 0.0


def _score_cell(paper: float, ours: float, tolerance: float) -> str:
    """paper→ours and the difference, coloured by the tolerance; wraps onto two lines in a narrow terminal."""
    colour = "green" if abs(ours - paper) <= tolerance + 1e-9 else "red"
    return f"{paper:.2f}→{ours:.2f} [{colour}]{_difference(ours, paper):+.2f}[/]"


def _outcome(collision: bool) -> str:
    return "collision" if collision else "avoided"


def _basis_lines(result: dict) -> list[str]:
    """Which Table II scores are collision zeros, calibrated values and out-of-sample checks, one line each."""
    from vrusim.paper.cases import BASES

    lines = []
    for basis, label in BASES.items():
        runs = []
        for case in result["cases"]:
            names = [name[0].upper() for name in SCORES if case["basis"][name] == basis]
            if names:
                runs.append(f"{case['title']} V2X {on_off(case['v2x'])} {'/'.join(names)}")
        lines.append(f"{label.capitalize()}: {'; '.join(runs)}.")
    return lines


def _table_ii(result: dict) -> Table:
    from vrusim.metrics.outcome import outcome_of

    tolerance = result["tolerances"]["score"]
    table = Table(
        title=f"Table II — outcomes and scores, paper→ours and difference (✓: all three within ±{tolerance:.2f})",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        show_edge=False,
    )
    table.add_column("Case")
    table.add_column("V2X")
    table.add_column("Outcome\npaper", no_wrap=True)
    table.add_column("Outcome\nours", no_wrap=True)
    for name in SCORES:
        table.add_column(name.capitalize(), justify="right")
    table.add_column(f"±{tolerance:.2f}", justify="center")
    for case in result["cases"]:
        paper, ours = case["paper"], case["ours"]
        colour = "green" if case["outcome_matches"] else "red"
        table.add_row(
            escape(case["title"]),
            on_off(case["v2x"]),
            _outcome(paper["collision"]),
            f"[{colour}]{outcome_of(ours)}[/]",
            *(_score_cell(paper[name], ours[name], tolerance) for name in SCORES),
            mark(case["scores_within_tolerance"]),
        )
    return table


def _events_table(result: dict) -> Table:
    tolerance = result["tolerances"]["time_s"]
    titles = {case["case"]: case["title"] for case in result["cases"]}
    table = Table(title=f"Event times from the figure captions (✓ within ±{tolerance:.1f} s)", box=box.SIMPLE_HEAD)
    table.add_column("Case")
    table.add_column("V2X")
    table.add_column("Event", ratio=1)
    table.add_column("Paper (s)", justify="right")
    table.add_column("Ours (s)", justify="right")
    table.add_column("Δ (s)", justify="right")
    table.add_column(f"±{tolerance:.1f} s", justify="center")
    for event in result["events"]:
        ours = event["ours_s"]
        table.add_row(
            escape(titles.get(event["case"], event["case"])),
            on_off(event["v2x"]),
            escape(event["event"]),
            number(event["paper_s"]),
            number(ours),
            "—" if ours is None else f"{_difference(ours, event['paper_s']):+.2f}",
            mark(event["within_tolerance"]),
        )
    return table


def paper_command(
    as_json: JsonOption = False,
    report: ReportOption = None,
    figures: Annotated[
        Path | None,
        file_option(
            "--figures",
            "DIR",
            "Also write per case a snapshot figure (rows V2X off / on) and a time-series figure as PNGs.",
        ),
    ] = None,
) -> None:
    """Reproduce the paper's three case studies (V2X off and on) and compare with its published results."""
    with user_errors():
        from vrusim.paper.cases import match_counts, match_summary, reproduce

        check_report_option(report)
        if figures is not None:
            check_figures_dir(figures)
        result = reproduce()
        figure_files = write_paper_figures(figures) if figures is not None else []
        if report is not None:
            from vrusim.report.paper import paper_report

            write_report_option(report, lambda: paper_report(result), quiet=as_json)
    if as_json:
        print_json(result)
        return
    terminal = console()
    terminal.print(_table_ii(result))
    for line in _basis_lines(result):
        terminal.print(escape(line))
    terminal.print(_events_table(result))
    if figure_files:
        terminal.print(f"Figures written to {escape(str(figures))}: {', '.join(f.name for f in figure_files)}.")
    counts = match_counts(result)
    all_match = all(ok == total for ok, total in counts.values())
    colour = "green" if all_match else "yellow"
    terminal.print(f"[{colour}]Matches: {match_summary(counts)}.[/]")
    terminal.print(
        "Scores by basis: calibrated = solved for by the `paper` profile (agree by construction); collision = "
        "0 whatever the formulas; out of sample = the checks (docs/paper.md)."
    )
    if not all_match:
        terminal.print('Where and why we differ from the paper: docs/paper.md, section "Where we differ, and why".')

"""`vrusim ncap` (run and assess the Euro NCAP catalogue) and `vrusim list` (show the catalogue)."""

from __future__ import annotations

import itertools
import time
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.options import V2XSwitch, console, print_json, user_errors
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.ncap.assess import Assessment
    from vrusim.ncap.protocol import NcapScenario


def _speed_grid(speeds: list[float]) -> str:
    """VUT speeds of a grid, compact: '10-60/5' or a list."""
    steps = {round(b - a, 6) for a, b in itertools.pairwise(speeds)}
    if len(speeds) > 2 and len(steps) == 1:
        return f"{speeds[0]:g}-{speeds[-1]:g}/{steps.pop():g}"
    return ", ".join(f"{s:g}" for s in speeds)


def catalogue_listing() -> list[dict]:
    """One JSON-ready row per catalogue scenario: its parameters, geometry and UNVERIFIED flags."""
    from vrusim.ncap.protocol import DUMMIES, SCENARIOS

    rows = []
    for s in SCENARIOS:
        targets = sorted({c.target or s.target for c in s.cells})
        locations = sorted({c.impact_location if c.impact_location is not None else s.impact_location for c in s.cells})
        geometry = {
            "layout": s.layout,
            "side": s.side,
            "turn": s.turn,
            "lateral_offset_m": s.lateral_offset_m,
            "start_to_impact_m": s.start_to_impact_m,
            "accel_distance_m": s.accel_distance_m,
            "steady_distance_m": s.steady_distance_m,
            "target_line_m": s.target_line_m,
            "headway_s": s.headway_s,
            "target_decel_mps2": s.target_decel_mps2,
        }
        rows.append(
            {
                "code": s.code,
                "group": s.group,
                "description": s.description,
                "function": s.function,
                "targets": targets,
                "target_speeds_kph": _target_speeds(s),
                "vut_speeds_kph": sorted({c.vut_speed_kph for c in s.cells}),
                "variants": [c.variant for c in s.cells if c.variant],
                "impact_locations_pct": [round(100 * x) for x in locations],
                "impact_side": s.impact_side,
                "geometry": {k: v for k, v in geometry.items() if v not in (0.0, None)},
                "lighting": list(s.lighting),
                "obstruction": s.obstruction,
                "extension": s.extension,
                "unverified": list(s.unverified) + [f"{t}: {flag}" for t in targets for flag in DUMMIES[t].unverified],
                "sources": s.sources,
                "tests": len(s.cells) * len(s.lighting),
            }
        )
    return rows


def _target_speeds(spec: NcapScenario) -> list[float] | str:
    """Target speeds of a scenario's grid, km/h; "vut" when the target drives at the VUT's speed (CMRb)."""
    if spec.headway_s > 0:
        return "vut"
    return sorted({round(c.target_speed_kph if c.target_speed_kph is not None else spec.target_speed_kph, 2)
                   for c in spec.cells})  # fmt: skip


def _geometry_text(geometry: dict) -> str:
    """Compact geometry: start offset / start→impact, acceleration and steady distances, headway."""
    labels = {
        "lateral_offset_m": "off",
        "start_to_impact_m": "d",
        "accel_distance_m": "acc",
        "steady_distance_m": "steady",
        "target_line_m": "line",
        "headway_s": "headway",
        "target_decel_mps2": "decel",
    }
    units = {"headway_s": " s", "target_decel_mps2": " m/s²"}
    parts = [f"{label} {geometry[key]:g}{units.get(key, ' m')}" for key, label in labels.items() if key in geometry]
    turn = f"{geometry['turn']} turn; " if "turn" in geometry else ""
    return turn + ", ".join(parts)


def list_catalogue(
    as_json: Annotated[bool, typer.Option("--json", help="Print the catalogue as one JSON document.")] = False,
) -> None:
    """Show every Euro NCAP catalogue entry with its parameters and flags."""
    rows = catalogue_listing()
    if as_json:
        print_json(rows)
        return
    table = Table(title="Euro NCAP AEB VRU catalogue (v4.5.1; E = vrusim extension, ! = unverified values)",
                  box=box.SIMPLE_HEAD)  # fmt: skip
    for name in ("Code", "Function", "Target", "km/h", "VUT km/h", "IL %", "Geometry", "Light", "Obstr.", "Tests"):
        table.add_column(name, overflow="fold" if name == "Geometry" else "ellipsis")
    table.add_column("Flags / unverified", overflow="fold")
    for row in rows:
        flags = ("E " if row["extension"] else "") + ("! " + "; ".join(row["unverified"]) if row["unverified"] else "")
        side = "" if row["impact_side"] == "front" else f" {row['impact_side']} side"
        table.add_row(
            row["code"],
            row["function"],
            "/".join(row["targets"]),
            "= VUT" if row["target_speeds_kph"] == "vut" else "/".join(f"{v:g}" for v in row["target_speeds_kph"]),
            _speed_grid(row["vut_speeds_kph"]),
            "/".join(str(p) for p in row["impact_locations_pct"]) + side,
            _geometry_text(row["geometry"]),
            "/".join(row["lighting"]),
            row["obstruction"] or "",
            str(row["tests"]),
            flags.strip(),
        )
    out = console()
    out.print(table)
    out.print(f"{len(rows)} scenarios, {sum(r['tests'] for r in rows)} tests (day and night).")


def register(app: typer.Typer) -> None:
    """Add the catalogue commands to the `vrusim` app."""
    app.command("list")(list_catalogue)
    app.command("ncap")(ncap)


def ncap(
    scenario: Annotated[
        list[str] | None,
        typer.Option("--scenario", help="Catalogue code or prefix (repeatable), e.g. CPNA-25, CPTA, CB. Default: all."),
    ] = None,
    planner: Annotated[
        str, typer.Option("--planner", help="fsm, none, aeb, predictive, module:Class or an entry-point name.")
    ] = "fsm",
    v2x: Annotated[V2XSwitch, typer.Option("--v2x", case_sensitive=False, help="Roadside unit on or off.")] = (
        V2XSwitch.off
    ),
    night: Annotated[bool, typer.Option("--night", help="Also run the night variants.")] = False,
    out: Annotated[
        Path | None, typer.Option("--out", metavar="DIR", help="Write results.csv, results.parquet, scorecard.png.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the assessment as one JSON document.")] = False,
    report: Annotated[
        Path | None,
        typer.Option(
            "--report", metavar="OUT.html", help="Also write a self-contained HTML report.", show_default=False
        ),
    ] = None,
) -> None:
    """Run the Euro NCAP AEB VRU grid in one batch and assess it the way Euro NCAP would."""
    with user_errors():
        from vrusim.ncap.assess import assess
        from vrusim.ncap.grid import run_tests, select
        from vrusim.planners.registry import make_planner

        if out is not None:
            prepare_out(out)
        if report is not None:
            from vrusim.report import check_output

            check_output(report, "--report")
        try:
            make_planner(planner)
        except UserInputError as error:
            raise UserInputError(str(error).replace("planner.name:", "--planner:", 1)) from None
        tests = select(scenario or [], night=night)
        started = time.perf_counter()
        result = run_tests(tests, planner=planner, v2x=v2x == V2XSwitch.on)
        elapsed = time.perf_counter() - started
        assessment = assess(result.rows)
        rows = result_rows(result.rows, assessment)
        written = write_outputs(out, rows, assessment) if out is not None else []
        if report is not None:
            from vrusim.cli.report import write_report_option
            from vrusim.report.ncap import ncap_report

            write_report_option(report, lambda: ncap_report(rows, assessment), quiet=True)
            written.append(report)
    if as_json:
        print_json({"planner": planner, "v2x": v2x.value, "night": night, "assessment": assessment.to_dict()})
        return
    from vrusim.viz.scorecard import scorecard_renderables

    terminal = console()
    for renderable in scorecard_renderables(assessment):
        terminal.print(renderable)
    terminal.print(
        f"{len(rows)} tests, planner {planner}, V2X {v2x.value}: simulated in one batch in {elapsed:.2f} s "
        f"({result.run.steps} steps)."
    )
    for path in written:
        terminal.print(f"Wrote {escape(str(path))}")


def result_rows(run_rows: list[dict], assessment: Assessment) -> list[dict]:
    """One row per test: the simulation's row joined with its assessment (colour, points, speeds in km/h)."""
    assessed = {test.test_id: asdict(test) for test in assessment.tests}
    return [row | assessed[row["test_id"]] for row in run_rows]


OUTPUT_FILES = ("results.csv", "results.parquet", "scorecard.png")
"""What `vrusim ncap --out DIR` writes."""


def prepare_out(folder: Path) -> None:
    """Create the --out folder before anything runs, and refuse targets that cannot be files."""
    if folder.exists() and not folder.is_dir():
        raise UserInputError(f"--out: {folder} exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise UserInputError(f"--out: cannot create {folder} ({error.strerror or error})") from None
    for name in OUTPUT_FILES:
        if (folder / name).is_dir():
            raise UserInputError(f"--out: {folder / name} is a folder; cannot write {name}")


def write_outputs(folder: Path, rows: list[dict], assessment: Assessment) -> list[Path]:
    """results.csv, results.parquet and scorecard.png in `folder`, written together: all or none."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    from vrusim.io.atomic import write_together
    from vrusim.viz.scorecard import scorecard_figure

    table = pa.Table.from_pylist(rows)
    figure = scorecard_figure(assessment)
    csv_name, parquet_name, png_name = OUTPUT_FILES
    return write_together(
        [
            (folder / csv_name, lambda temp: pa_csv.write_csv(table, temp), "results"),
            (folder / parquet_name, lambda temp: pq.write_table(table, temp), "results"),
            (folder / png_name, lambda temp: figure.savefig(temp, format="png"), "scorecard"),
        ]
    )

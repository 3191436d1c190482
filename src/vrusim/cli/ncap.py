"""`vrusim ncap` (run and assess the Euro NCAP catalogue) and `vrusim list` (show the catalogue)."""

from __future__ import annotations

import itertools
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.ncap2026 import OUTPUT_FILES
from vrusim.cli.options import (
    ForceOption,
    JsonOption,
    ReportOption,
    V2XSwitch,
    check_out_dir,
    file_option,
    one_planner,
    out_dir_option,
    planner_option,
    seed_option,
    v2x_switch_option,
)
from vrusim.cli.output import console, print_json, user_errors
from vrusim.cli.report import check_report_option, write_report_option
from vrusim.errors import UserInputError

if TYPE_CHECKING:
    from vrusim.cli.ncap2026 import Options2026
    from vrusim.ncap.assess import Assessment

GEOMETRY_LABELS = {
    "lateral_offset_m": "off",
    "start_to_impact_m": "d",
    "accel_distance_m": "acc",
    "steady_distance_m": "steady",
    "target_line_m": "line",
    "headway_s": "headway",
    "target_decel_mps2": "decel",
}
"""Short labels of the geometry fields in `vrusim list`."""
GEOMETRY_UNITS = {"headway_s": " s", "target_decel_mps2": " m/s²"}


def protocol_option() -> typer.models.OptionInfo:
    """`--protocol EDITION`: which Euro NCAP edition's tables (ncap/editions)."""
    from vrusim.ncap.editions import DEFAULT_EDITION, EDITION_NAMES

    return typer.Option(
        "--protocol",
        help=f"Euro NCAP edition: {' or '.join(EDITION_NAMES)} (default {DEFAULT_EDITION}).",
        metavar="EDITION",
    )


ProtocolOption = Annotated[str | None, protocol_option()]


# ----------------------------------------------------------------------------------------------- vrusim list


def _speed_grid(speeds: list[float]) -> str:
    """VUT speeds of a grid, compact: '10-60/5' or a list."""
    steps = {round(b - a, 6) for a, b in itertools.pairwise(speeds)}
    if len(speeds) > 2 and len(steps) == 1:
        return f"{speeds[0]:g}-{speeds[-1]:g}/{steps.pop():g}"
    return ", ".join(f"{s:g}" for s in speeds)


def _geometry_text(geometry: dict) -> str:
    """Compact geometry: start offset / start→impact, acceleration and steady distances, headway."""
    parts = [
        f"{label} {geometry[key]:g}{GEOMETRY_UNITS.get(key, ' m')}"
        for key, label in GEOMETRY_LABELS.items()
        if key in geometry
    ]
    turn = f"{geometry['turn']} turn; " if "turn" in geometry else ""
    return turn + ", ".join(parts)


def _grid_table(rows: list[dict], title: str) -> Table:
    """Per scenario: function, targets and speeds, impact location, lighting, test count."""
    table = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left")
    for name in ("Code", "Function", "Target", "Target\nkm/h", "VUT\nkm/h", "Impact\nat %", "Light", "Tests"):
        table.add_column(name, justify="right" if name == "Tests" else "left")
    for row in rows:
        side = "" if row["impact_side"] == "front" else f" {row['impact_side']} side"
        table.add_row(
            row["code"],
            row["function"],
            ", ".join(row["targets"]),
            "= VUT" if row["target_speeds_kph"] == "vut" else "/".join(f"{v:g}" for v in row["target_speeds_kph"]),
            _speed_grid(row["vut_speeds_kph"]),
            "/".join(str(p) for p in row["impact_locations_pct"]) + side,
            ", ".join(row["lighting"]),
            str(row["tests"]),
        )
    return table


def _details_table(rows: list[dict]) -> Table:
    """Per scenario: geometry, obstruction and flags (E = vrusim extension, ! = unverified values)."""
    table = Table(
        title="Geometry and flags (E = vrusim extension, ! = unverified values)",
        box=box.SIMPLE_HEAD,
        title_justify="left",
    )
    table.add_column("Code")
    table.add_column("Geometry")
    table.add_column("Obstruction")
    table.add_column("Flags / unverified")
    for row in rows:
        flags = ("E " if row["extension"] else "") + ("! " + "; ".join(row["unverified"]) if row["unverified"] else "")
        table.add_row(row["code"], _geometry_text(row["geometry"]), row["obstruction"] or "", flags.strip())
    return table


def list_command(protocol: ProtocolOption = None, as_json: JsonOption = False) -> None:
    """Show every Euro NCAP catalogue entry of an edition with its parameters and flags."""
    with user_errors():
        from vrusim.ncap.editions import edition
        from vrusim.ncap.listing import catalogue_listing

        book = edition(protocol)
        rows = catalogue_listing(book.name)
    if as_json:
        print_json(rows)
        return
    out = console()
    out.print(_grid_table(rows, book.title))
    out.print(_details_table(rows))
    out.print(f"{len(rows)} scenarios, {sum(r['tests'] for r in rows)} tests (day and night).")


# ----------------------------------------------------------------------------------------------- vrusim ncap


def ncap_command(
    scenario: Annotated[
        list[str] | None,
        typer.Option("--scenario", help="Catalogue code or prefix (repeatable), e.g. CPNA, CPTA, CB. Default: all."),
    ] = None,
    protocol: ProtocolOption = None,
    planner: Annotated[list[str] | None, planner_option("fsm")] = None,
    v2x: Annotated[V2XSwitch, v2x_switch_option("Roadside unit on or off.")] = V2XSwitch.off,
    night: Annotated[bool, typer.Option("--night", help="Also run the night variants.")] = False,
    out: Annotated[Path | None, out_dir_option("results.csv, results.parquet and scorecard.png")] = None,
    force: ForceOption = False,
    predictions: Annotated[
        Path | None,
        file_option("--predictions", "OUT.xlsx", "2026: fill Euro NCAP's prediction template (extra ncap2026)."),
    ] = None,
    verify: Annotated[
        int,
        typer.Option(
            "--verify", metavar="DRAWS", help="2026: simulate DRAWS laboratory verifications (FC26 §4). Default: 0."
        ),
    ] = 0,
    seed: Annotated[int | None, seed_option("Seed of the verification draws (default 0).")] = None,
    as_json: JsonOption = False,
    report: ReportOption = None,
) -> None:
    """Run a Euro NCAP VRU grid in one batch and assess it the way Euro NCAP would."""
    with user_errors():
        from vrusim.cli.ncap2026 import check_2026_options
        from vrusim.ncap.editions import edition
        from vrusim.ncap.grid import select

        chosen = one_planner(planner, "ncap") or "fsm"
        book = edition(protocol)
        tests = select(scenario or [], night=night, protocol=book.name)
        options = check_2026_options(book.name, predictions, verify, seed, out)
        if out is not None:
            _check_out(out, force)
        check_report_option(report)
        if book.name == "2026":
            _ncap_2026(tests, chosen, v2x == V2XSwitch.on, options, out, report, as_json)
            return
        _ncap_2023(tests, chosen, v2x, night, out, report, as_json)


def _ncap_2026(
    tests: list, planner: str, v2x: bool, options: Options2026, out: Path | None, report: Path | None, as_json: bool
) -> None:
    from vrusim.cli.ncap2026 import print_2026, run_2026, write_2026_outputs

    with user_errors():
        rated, elapsed = run_2026(tests, planner, v2x)
        verification = rated.verify(options.verify_draws, options.seed) if options.verify_draws else None
        written = write_2026_outputs(rated, verification, out, options.predictions)
        if report is not None:
            from vrusim.ncap.results2026 import result_rows_2026
            from vrusim.report.ncap2026 import ncap_2026_report

            rows = result_rows_2026(rated.catalogue_run.rows, rated.assessment, verification)
            write_report_option(report, lambda: ncap_2026_report(rows, rated.assessment, verification), quiet=True)
            written.append(report)
    print_2026(rated, verification, elapsed, written, as_json)


def _ncap_2023(
    tests: list, chosen: str, v2x: V2XSwitch, night: bool, out: Path | None, report: Path | None, as_json: bool
) -> None:
    with user_errors():
        from vrusim.ncap.assess import assess, result_rows
        from vrusim.ncap.grid import run_tests

        started = time.perf_counter()
        result = run_tests(tests, planner=chosen, v2x=v2x == V2XSwitch.on)
        elapsed = time.perf_counter() - started
        assessment = assess(result.rows)
        rows = result_rows(result.rows, assessment)
        written = _write_outputs(out, rows, assessment) if out is not None else []
        if report is not None:
            from vrusim.report.ncap import ncap_report

            write_report_option(report, lambda: ncap_report(rows, assessment), quiet=True)
            written.append(report)
    if as_json:
        print_json(
            {
                "protocol": "2023",
                "planner": chosen,
                "v2x": v2x.value,
                "night": night,
                "assessment": assessment.to_dict(),
            }
        )
        return
    from vrusim.viz.scorecard_terminal import scorecard_renderables

    terminal = console()
    for renderable in scorecard_renderables(assessment):
        terminal.print(renderable)
    terminal.print(
        f"{len(rows)} tests, planner {chosen}, V2X {v2x.value}: simulated in one batch in {elapsed:.2f} s "
        f"({result.run.steps} steps)."
    )
    for path in written:
        terminal.print(f"Wrote {escape(str(path))}")


def _check_out(folder: Path, force: bool) -> None:
    """Refuse, before anything runs, an --out that cannot be written into, is not empty (without --force), or whose
    targets cannot be files. The folder is created only when the results are written."""
    check_out_dir(folder, force)
    for name in OUTPUT_FILES:
        if (folder / name).is_dir():
            raise UserInputError(f"--out: {folder / name} is a folder; cannot write {name}")


def _write_outputs(folder: Path, rows: list[dict], assessment: Assessment) -> list[Path]:
    """results.csv, results.parquet and scorecard.png in `folder`, written together: all or none."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    from vrusim.io.atomic import write_together
    from vrusim.io.paths import for_option, new_folder
    from vrusim.viz.scorecard import scorecard_figure

    table = pa.Table.from_pylist(rows)
    figure = scorecard_figure(assessment)
    csv_name, parquet_name, png_name = OUTPUT_FILES[:3]
    with new_folder(folder, "--out"), for_option("--out"):
        return write_together(
            [
                (folder / csv_name, lambda temp: pa_csv.write_csv(table, temp), "results"),
                (folder / parquet_name, lambda temp: pq.write_table(table, temp), "results"),
                (folder / png_name, lambda temp: figure.savefig(temp, format="png"), "scorecard"),
            ]
        )

"""`vrusim ncap` (run and assess the Euro NCAP catalogue) and `vrusim list` (show the catalogue)."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Annotated

import typer
from rich import box
from rich.table import Table

from vrusim.cli_support import V2XSwitch, console, print_json
from vrusim.errors import UserInputError


def _speed_grid(speeds: list[float]) -> str:
    """VUT speeds of a grid, compact: '10-60/5' or a list."""
    steps = {round(b - a, 6) for a, b in itertools.pairwise(speeds)}
    if len(speeds) > 2 and len(steps) == 1:
        return f"{speeds[0]:g}-{speeds[-1]:g}/{steps.pop():g}"
    return ", ".join(f"{s:g}" for s in speeds)


def catalogue_listing() -> list[dict]:
    """One JSON-ready row per catalogue scenario: its parameters and flags."""
    from vrusim.catalog.ncap_protocol import SCENARIOS

    return [
        {
            "code": s.code,
            "group": s.group,
            "description": s.description,
            "function": s.function,
            "target": s.target,
            "target_speed_kph": round(s.target_speed_kph, 3),
            "vut_speeds_kph": sorted({c.vut_speed_kph for c in s.cells}),
            "variants": [c.variant for c in s.cells if c.variant],
            "impact_location_pct": round(100 * s.impact_location),
            "lighting": list(s.lighting),
            "obstruction": s.obstruction,
            "extension": s.extension,
            "unverified": list(s.unverified),
            "sources": s.sources,
            "tests": len(s.cells) * len(s.lighting),
        }
        for s in SCENARIOS
    ]


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
    for name in ("Code", "Group", "Function", "Target", "km/h", "VUT km/h", "IL %", "Light", "Obstr.", "Tests"):
        table.add_column(name)
    table.add_column("Flags / unverified", overflow="fold")
    for row in rows:
        flags = ("E " if row["extension"] else "") + ("! " + "; ".join(row["unverified"]) if row["unverified"] else "")
        table.add_row(
            row["code"],
            row["group"],
            row["function"],
            row["target"],
            f"{row['target_speed_kph']:g}",
            _speed_grid(row["vut_speeds_kph"]),
            str(row["impact_location_pct"]),
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
    planner: Annotated[str, typer.Option("--planner", help="fsm, none or module:Class.")] = "fsm",
    v2x: Annotated[V2XSwitch, typer.Option("--v2x", case_sensitive=False, help="Roadside unit on or off.")] = (
        V2XSwitch.off
    ),
    night: Annotated[bool, typer.Option("--night", help="Also run the night variants.")] = False,
    out: Annotated[
        Path | None, typer.Option("--out", metavar="DIR", help="Write results.csv, results.parquet, scorecard.png.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the assessment as one JSON document.")] = False,
) -> None:
    """Run the Euro NCAP AEB VRU grid in one batch and assess it the way Euro NCAP would."""
    raise UserInputError("not implemented yet")

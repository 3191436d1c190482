"""`vrusim compare`: planners × V2X settings on one scenario (a YAML file or a catalogue test), side by side."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich import box
from rich.table import Table

from vrusim.cli.options import OneSource, console, print_json, user_errors


def _names(option: str, value: str) -> list[str]:
    names = [name.strip() for name in value.split(",") if name.strip()]
    if not names:
        from vrusim.errors import UserInputError

        raise UserInputError(f"{option}: expected a comma-separated list of names")
    return list(dict.fromkeys(names))


def _num(value: float | None, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def compare_command(
    source: OneSource,
    planners: Annotated[str, typer.Option("--planners", help="Comma-separated planners.")] = "fsm",
    v2x: Annotated[
        str, typer.Option("--v2x", help="Comma-separated V2X settings: 'off' or a channel profile name.")
    ] = "off,ideal",
    profiles: Annotated[
        Path | None, typer.Option("--profiles", metavar="FILE.yaml", help="Extra named channel profiles.")
    ] = None,
    seeds: Annotated[int, typer.Option("--seeds", help="Seeded variants per combination (random channels).")] = 1,
    as_json: Annotated[bool, typer.Option("--json", help="Print the rows as one JSON document.")] = False,
) -> None:
    """Run every planner with every V2X setting on one scenario and compare outcomes and scores."""
    with user_errors():
        from vrusim.sources import single_source
        from vrusim.studies.compare import compare

        base = single_source(source, catalogue_v2x=True)  # a catalogue test brings its roadside unit
        channels = _user_channels(profiles) if profiles is not None else None
        rows = compare(base, _names("--planners", planners), _names("--v2x", v2x), seeds, channels)
    if as_json:
        print_json(rows)
        return
    table = Table(title=f"{base.name}: planners × V2X ({seeds} seed{'s' if seeds > 1 else ''} each)",
                  box=box.SIMPLE_HEAD)  # fmt: skip
    for name in ("Planner", "V2X", "Collision", "P 95 %", "Impact m/s", "min TTC s", "Sensor s", "V2X s"):
        table.add_column(name, justify="left" if name in ("Planner", "V2X") else "right")
    for name in ("Safety", "Efficiency", "Comfort"):
        table.add_column(name, justify="right")
    for row in rows:
        low, high = row["collision_probability_95"]
        outcome = f"{row['collisions']}/{row['runs']}"
        style = "red" if row["collisions"] else "green"
        table.add_row(
            row["planner"],
            row["v2x"],
            f"[{style}]{outcome}[/]",
            f"{low:.2f}–{high:.2f}",
            _num(row["mean_impact_speed_mps"]),
            _num(row["min_ttc_s"]),
            _num(row["mean_first_sensor_detection_s"]),
            _num(row["mean_first_v2x_message_s"]),
            _num(row["safety"]),
            _num(row["efficiency"]),
            _num(row["comfort"]),
        )
    console().print(table)


def _user_channels(path: Path) -> dict[str, dict]:
    """Channel profiles from a YAML file, as inline specifications by name."""
    from vrusim.scenario.v2x import load_profiles

    return {name: spec.model_dump() for name, spec in load_profiles(path).items()}


def register(app: typer.Typer) -> None:
    """Add `compare` to the `vrusim` app."""
    app.command("compare")(compare_command)

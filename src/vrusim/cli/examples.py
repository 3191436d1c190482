"""`vrusim examples`: the scenarios and sweep specs bundled with vrusim, by the names the commands accept."""

from __future__ import annotations

from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.options import JsonOption
from vrusim.cli.output import console, print_json, user_errors

USE = {"scenario": "vrusim run {name}", "sweep": "vrusim sweep {name} --dry-run"}
"""How each kind is used, shown next to it."""


def examples_command(as_json: JsonOption = False) -> None:
    """List the bundled scenarios and sweep specs (they work from an installed wheel too)."""
    with user_errors():
        from vrusim.sources import bundled

        entries = bundled()
    if as_json:
        print_json(
            [
                {"name": e.name, "kind": e.kind, "description": e.description, "path": str(e.path), "try": _use(e)}
                for e in entries
            ]
        )
        return
    table = Table(title="Bundled examples", box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("Name", no_wrap=True)
    table.add_column("Kind")
    table.add_column("Description", ratio=1)
    for entry in entries:
        table.add_row(escape(entry.name), entry.kind, escape(entry.description))
    terminal = console()
    terminal.print(table)
    terminal.print(
        "Run a scenario by name (`vrusim run paper:pedestrian`), or give it to compare, report and export; "
        "run a sweep spec by name (`vrusim sweep example:pedestrian-monte-carlo --out DIR`)."
    )


def _use(entry) -> str:
    return USE[entry.kind].format(name=entry.name)

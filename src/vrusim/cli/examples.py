"""`vrusim examples`: the scenarios and sweep specs bundled with vrusim, by the names the commands accept."""

from __future__ import annotations

from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.options import JsonOption
from vrusim.cli.output import console, print_json, user_errors

COMMANDS = {"scenario": "vrusim run {name}", "sweep": "vrusim sweep {name} --dry-run"}
"""A command that uses a bundled entry, by its kind (in the JSON listing)."""


def examples_command(as_json: JsonOption = False) -> None:
    """List the bundled scenarios and sweep specs (they work from an installed wheel too)."""
    with user_errors():
        from vrusim.sources import bundled

        entries = bundled()
    if as_json:
        listing = [
            {"name": e.name, "kind": e.kind, "description": e.description, "path": str(e.path)}
            | {"command": COMMANDS[e.kind].format(name=e.name)}
            for e in entries
        ]
        print_json(listing)
        return
    table = Table(title="Bundled examples", box=box.SIMPLE_HEAD, title_justify="left")
    table.add_column("Name", no_wrap=True)
    table.add_column("Kind")
    table.add_column("Description")
    for entry in entries:
        table.add_row(escape(entry.name), entry.kind, escape(entry.description))
    terminal = console()
    terminal.print(table)
    terminal.print(
        "Run a scenario by name (`vrusim run paper:pedestrian`), or give it to compare, report and export; "
        "run a sweep spec by name (`vrusim sweep example:pedestrian-monte-carlo --out DIR`)."
    )

"""`vrusim view SOURCE`: write the scene-player page of a run (or of V2X off and on compared) and open it.

SOURCE is a scenario (file, bundled name or catalogue test id) or a saved trace (`vrusim run --trace OUT.csv`)
with `--scenario` naming the scenario it ran. The page goes to `--out` (default: vrusim-view-NAME.html in the
system's temporary folder) and opens in the default browser unless `--no-open`, VRUSIM_NO_BROWSER=1, or no
browser is available; the path is printed either way.
"""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from vrusim.cli.options import JsonOption, file_option, one_planner, planner_option, seed_option, split_names
from vrusim.cli.output import console, print_json, user_errors
from vrusim.errors import UserInputError

NO_BROWSER_ENV = "VRUSIM_NO_BROWSER"
"""Set to 1 to never open a browser (tests, scripts)."""


def _v2x_settings(value: str | None) -> list[bool | None]:
    """--v2x: off, on, or a comma list of them (one run each, compared); None: the scenario's own."""
    if value is None:
        return [None]
    names = split_names([value], "--v2x")
    unknown = [name for name in names if name.lower() not in ("off", "on")]
    if unknown or not names:
        raise UserInputError(f"--v2x: expected off, on or off,on; got {value!r}")
    return [name.lower() == "on" for name in dict.fromkeys(names)]


def _default_out(name: str) -> Path:
    slug = re.sub(r"[^A-Za-z0-9._-]+", "-", name).strip("-") or "run"
    return Path(tempfile.gettempdir()) / f"vrusim-view-{slug}.html"


def view_command(
    source: Annotated[
        str,
        typer.Argument(
            metavar="SOURCE",
            help="A scenario YAML file, a bundled scenario (paper:pedestrian), a catalogue test id, or a saved trace "
            "(.csv / .parquet from `vrusim run --trace`, with --scenario).",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path | None, file_option("--out", "PAGE.html", "The page to write (default: in the temporary folder).")
    ] = None,
    v2x: Annotated[
        str | None,
        typer.Option("--v2x", metavar="off|on|off,on", help="Force V2X off or on; off,on compares both runs."),
    ] = None,
    planner: Annotated[list[str] | None, planner_option("the scenario file's (fsm for a catalogue test)")] = None,
    seed: Annotated[int | None, seed_option("Key of the run's random numbers. Default: the file's.")] = None,
    scenario: Annotated[
        str | None,
        typer.Option("--scenario", metavar="SCENARIO", help="Saved trace only: the scenario it ran (for the drawing)."),
    ] = None,
    no_open: Annotated[bool, typer.Option("--no-open", help=f"Do not open a browser (as {NO_BROWSER_ENV}=1).")] = False,
    as_json: JsonOption = False,
) -> None:
    """Write a scene-player page of one run (or V2X off and on compared) and open it in the default browser."""
    with user_errors():
        from vrusim.engine.trace_file import TRACE_SUFFIXES
        from vrusim.io.paths import check_output_file
        from vrusim.report import check_output, write_report
        from vrusim.report.view import read_trace_recording, view_report
        from vrusim.sources import apply_planner_and_seed, scenario_of

        chosen = one_planner(planner, "view")
        settings = _v2x_settings(v2x)
        saved = Path(source).suffix.lower() in TRACE_SUFFIXES
        if saved:
            if scenario is None:
                raise UserInputError("--scenario: a saved trace needs the scenario it ran, to draw the road and actors")
            for option, value in (("--v2x", v2x), ("--planner", chosen), ("--seed", seed)):
                if value is not None:
                    raise UserInputError(f"{option}: not for a saved trace (it ran as it ran)")
            if not Path(source).is_file():
                raise UserInputError(f"SOURCE: trace file {source} not found")
            base = scenario_of(scenario, argument="--scenario")
        elif scenario is not None:
            raise UserInputError("--scenario: only with a saved trace as SOURCE (.csv or .parquet)")
        if out is not None:
            check_output(check_output_file(out, "--out"))
        if saved:
            recordings = [read_trace_recording(Path(source), base)]
            note = f"trace {source} with scenario {scenario}"
        else:
            from vrusim.viz.recording import record

            scenarios = [
                apply_planner_and_seed(scenario_of(source, setting, option="--v2x"), chosen, seed)
                for setting in settings
            ]
            recordings = [record([s])[0] for s in scenarios]
            note = source
        target = out if out is not None else _default_out(recordings[0].scenario.name)
        size = write_report(view_report(recordings, note=note), target)
    opened = False
    if not (no_open or os.environ.get(NO_BROWSER_ENV) == "1"):
        import webbrowser

        try:
            opened = webbrowser.open(target.resolve().as_uri())
        except webbrowser.Error:
            opened = False
    if as_json:
        print_json({"out": str(target), "bytes": size, "opened": opened})
        return
    where = "opened in the browser" if opened else "open it in a browser"
    console().print(f"Wrote {escape(str(target))} ({size / 1024:.0f} KiB); {where}.")

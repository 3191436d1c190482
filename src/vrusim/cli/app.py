"""The `vrusim` command line: the Typer app, its commands (one module each) and the console-script entry point.

    vrusim run SOURCE [--planner NAME] [--v2x on|off] [--seed N] [--json] [--trace|--plot|--animate OUT]
    vrusim paper | ncap | list | compare | sweep | summarize | report | view | export | import | examples | compile
    (`vrusim CMD --help` for each)
    vrusim --version

Bad input (a scenario field, a file, an option) ends with one message on stderr naming the culprit and exit
code 2, never a traceback; anything else that goes wrong is a bug and keeps its traceback. A cold start (kernels
not yet compiled for this version) says so on stderr while it compiles; stdout stays the command's output.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Callable, Sequence
from typing import Annotated

import typer

from vrusim.cli.compare import compare_command
from vrusim.cli.compile import compile_command
from vrusim.cli.examples import examples_command
from vrusim.cli.export import export_command
from vrusim.cli.help import Command, Group
from vrusim.cli.importing import import_command
from vrusim.cli.ncap import list_command, ncap_command
from vrusim.cli.output import USER_ERROR_EXIT_CODE, report_user_error
from vrusim.cli.paper import paper_command
from vrusim.cli.report import report_command
from vrusim.cli.run import run_command
from vrusim.cli.summarize import summarize_command
from vrusim.cli.sweep import sweep_command
from vrusim.cli.view import view_command
from vrusim.errors import UserInputError
from vrusim.kernel_notices import compile_notices
from vrusim.planners.permission import MODULE_PLANNERS_ENV, MODULE_PLANNERS_FLAG, allow_module_planners
from vrusim.version import __version__

COMMANDS: dict[str, Callable[..., None]] = {
    "run": run_command,
    "paper": paper_command,
    "list": list_command,
    "ncap": ncap_command,
    "compare": compare_command,
    "sweep": sweep_command,
    "summarize": summarize_command,
    "report": report_command,
    "view": view_command,
    "export": export_command,
    "import": import_command,
    "examples": examples_command,
    "compile": compile_command,
}
"""Every command by name, in the order `vrusim --help` lists them."""

app = typer.Typer(
    name="vrusim",
    help="Closed-loop simulation of Euro NCAP vulnerable-road-user tests with perception, V2X and planners.",
    cls=Group,
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"vrusim {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", help="Print the version and exit.", callback=_version_callback, is_eager=True),
    ] = False,
    allow_modules: Annotated[
        bool,
        typer.Option(
            MODULE_PLANNERS_FLAG,
            help=f"Let planner names of the form module:Class import their Python module (as {MODULE_PLANNERS_ENV}=1"
            "). A scenario file is data: without this, vrusim imports no code it names.",
        ),
    ] = False,
) -> None:
    """Closed-loop simulation of Euro NCAP vulnerable-road-user tests with perception, V2X and planners."""
    if allow_modules:
        allow_module_planners()


for _name, _command in COMMANDS.items():
    app.command(_name, cls=Command)(_command)


def main(argv: Sequence[str] | None = None, prog_name: str = "vrusim") -> None:
    """Console-script entry point: run the app; any UserInputError becomes its message and exit code 2. Kernels
    that compile (a cold start) are announced on stderr, one line per kernel (`vrusim.kernel_notices`).

    Without `argv` (the process's own command line: the console script, `python -m vrusim`) the process is the
    command's: the garbage collector runs less often (`_collect_rarely`) and is frozen before the process ends
    (`_before_exit`); with `argv` (a caller that goes on, e.g. a test) it is left alone.
    """
    if argv is None:
        _collect_rarely()
    try:
        with compile_notices():
            app(args=None if argv is None else list(argv), prog_name=prog_name)
    except UserInputError as error:
        report_user_error(error)
        sys.exit(USER_ERROR_EXIT_CODE)
    finally:
        if argv is None:
            _before_exit()


GC_THRESHOLDS = (50_000, 20, 10)
"""The garbage collector's thresholds in the command's own process (Python's default: 700, 10, 10)."""


def _collect_rarely() -> None:
    """Let the collector wait for 50,000 new container objects instead of 700 before it looks for cycles.

    A command imports numba, pydantic and the kernels' modules (some 100,000 objects, all alive until the end),
    and Python's default thresholds make the collector go over them again and again while they are created:
    about 0.1 s of `vrusim ncap`. Cycles are still collected, only in larger batches.
    """
    gc.set_threshold(*GC_THRESHOLDS)


def _before_exit() -> None:
    """Freeze the garbage collector: the interpreter's shutdown then skips its collections over every object
    alive (numba's compiler and pydantic's schemas alone are some 100,000), about 0.2 s of a command's wall
    time. Shutdown is otherwise unchanged (atexit handlers run, streams are flushed, objects freed)."""
    gc.freeze()

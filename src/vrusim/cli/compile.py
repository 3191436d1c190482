"""`vrusim compile`: compile the simulation kernels ahead of time, so that no later command waits for them."""

from __future__ import annotations

from typing import Annotated, Any

import typer

from vrusim.cli.options import JsonOption, split_names
from vrusim.cli.output import print_json, user_errors


def _starting(tasks: list, processes: int) -> None:
    typer.echo(f"vrusim: compiling the kernels of {len(tasks)} tasks in {processes} processes at once", err=True)


def _progress(task, seconds: float, done: int, total: int) -> None:
    typer.echo(f"vrusim: [{done}/{total}] {task.name} ready in {seconds:.1f} s", err=True)


def _names_option(name: str, metavar: str, help: str) -> Any:
    """A repeatable option that also takes a comma list."""
    return typer.Option(name, metavar=metavar, help=f"{help} Repeatable, or a comma list.", show_default=False)


def compile_command(
    planner: Annotated[
        list[str] | None,
        _names_option(
            "--planner",
            "NAME",
            "Built-in planners to compile for: fsm, none, aeb, predictive, acpe, reverse_aeb, dow. Default: fsm, "
            "none, aeb, predictive (the planners with a compiled step).",
        ),
    ] = None,
    part: Annotated[
        list[str] | None,
        _names_option(
            "--part",
            "PART",
            "What to compile: compiled (the compiled step: run, paper, sweep), ncap (the Euro NCAP grids' drivers, "
            "doors, obstacles and probes), per-step (traces, plots, animations, plug-in planners), threaded (the "
            "per-step path's batches of 4,096 variants or more). Default: all four.",
        ),
    ] = None,
    jobs: Annotated[
        int | None,
        typer.Option(
            "--jobs",
            metavar="N",
            help="Processes at once. Default: the cores this process may use.",
            show_default=False,
        ),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """Compile the simulation kernels now (for a container image or a CI cache), so later commands load them."""
    with user_errors():
        from vrusim.api.compiling import compile_kernels
        from vrusim.api.settings import renamed
        from vrusim.errors import UserInputError

        try:
            report = compile_kernels(
                split_names(planner, "--planner") or None,
                split_names(part, "--part") or None,
                jobs,
                _progress,
                _starting,
            )
        except UserInputError as error:
            raise renamed(error, {"planners:": "--planner:", "parts:": "--part:", "jobs:": "--jobs:"}) from None
    if as_json:
        print_json(
            {
                "folder": report.folder,
                "wall_s": round(report.wall_s, 3),
                "tasks_s": {name: round(seconds, 3) for name, seconds in report.seconds.items()},
            }
        )
        return
    typer.echo(f"Kernels ready in {report.folder}: {len(report.seconds)} tasks in {report.wall_s:.1f} s.")

"""What a report is made from (a scenario file, the paper, an ncap folder, a sweep folder) and writing it.

Every check on SOURCE and on the output path happens before anything runs; the file is written atomically,
so a failure leaves no half-written report (and an existing one untouched).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from enum import StrEnum
from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.io.atomic import write_atomically
from vrusim.io.paths import check_name
from vrusim.report.page import Report, render
from vrusim.sources import SCENARIO_FILE_SUFFIXES, is_bundled_name, scenario_file, single_test

REPORT_SUFFIXES = (".html", ".htm")
NCAP_RESULTS = "results.parquet"
SWEEP_MANIFEST = "manifest.json"
EXPECTED = (
    "a scenario file (.yaml, or OpenSCENARIO .xosc), a bundled scenario (`vrusim examples`), a Euro NCAP test "
    "id, the word 'paper', a `vrusim ncap --out` folder or a sweep results folder"
)


class SourceKind(StrEnum):
    """The four kinds of report."""

    run = "run"
    paper = "paper"
    ncap = "ncap"
    sweep = "sweep"


def source_kind(source: str, argument: str = "SOURCE") -> SourceKind:
    """Which report SOURCE asks for; a UserInputError naming `argument` when it is none of them."""
    if source == "paper":
        return SourceKind.paper
    if is_bundled_name(source):
        scenario_file(source, argument)  # a bundled scenario, or a user error with close names
        return SourceKind.run
    path = check_name(source, argument)  # a null byte or a name too long: not a file, not an id
    if not path.exists():
        if path.suffix.lower() in SCENARIO_FILE_SUFFIXES:
            raise UserInputError(f"{argument}: {source} not found; expected {EXPECTED}")
        single_test(source, EXPECTED)  # a catalogue test id, or a user error with close ids
        return SourceKind.run
    if path.is_dir():
        if (path / SWEEP_MANIFEST).is_file():
            return SourceKind.sweep
        if (path / NCAP_RESULTS).is_file():
            return SourceKind.ncap
        raise UserInputError(
            f"{argument}: folder {source} has neither {SWEEP_MANIFEST} (a sweep results folder) nor "
            f"{NCAP_RESULTS} (a `vrusim ncap --out` folder)"
        )
    if path.suffix.lower() in SCENARIO_FILE_SUFFIXES:
        return SourceKind.run
    raise UserInputError(f"{argument}: {source} is not a scenario file (.yaml, .yml or .xosc); expected {EXPECTED}")


def check_output(path: Path, option: str = "--out") -> None:
    """Refuse, before any work, an output path without .html, inside a missing folder, or not writable."""
    if path.suffix.lower() not in REPORT_SUFFIXES:
        raise UserInputError(f"{option}: {path} must end in .html (the report is one HTML file)")
    if path.is_dir():
        raise UserInputError(f"{option}: {path} is a folder")
    folder = path.parent
    if not folder.is_dir():
        raise UserInputError(f"{option}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise UserInputError(f"{option}: cannot write {path} (permission denied)")


def build_report(
    source: str,
    v2x: bool | None = None,
    bins: int = 10,
    planner: str | None = None,
    seed: int | None = None,
    players: Sequence[str] = (),
) -> Report:
    """The report of SOURCE (see `source_kind`); `v2x`, `planner` and `seed` are forced on a run of a scenario (file,
    bundled or catalogue test), `bins` groups sweeps, `players` adds a scene player of each named test to an ncap
    report."""
    kind = source_kind(source)
    if players and kind is not SourceKind.ncap:
        raise UserInputError("--player: only for a `vrusim ncap --out` folder (a run report has its player)")
    for option, value in (("--v2x", v2x), ("--planner", planner), ("--seed", seed)):
        if value is not None and kind is not SourceKind.run:
            raise UserInputError(f"{option}: only applies to a scenario file or a catalogue test")
    if kind is SourceKind.paper:
        from vrusim.report.paper import paper_report

        return paper_report()
    if kind is SourceKind.run:
        from vrusim.report.run import run_report

        return run_report(source, v2x, planner, seed)
    if kind is SourceKind.ncap:
        from vrusim.report.ncap import ncap_report_from_folder, read_rows

        report = ncap_report_from_folder(Path(source))
        if players:
            from vrusim.report.ncap_player import test_players

            report = replace(report, sections=[*report.sections, *test_players(read_rows(Path(source)), players)])
        return report
    from vrusim.report.sweep import sweep_report

    return sweep_report(Path(source), bins)


def write_report(report: Report, path: Path, option: str = "--out") -> int:
    """Render and write the report atomically; its size in bytes."""
    data = render(report).encode("utf-8")
    try:
        write_atomically(path, lambda temp: temp.write_bytes(data), "report")
    except UserInputError as error:
        raise UserInputError(f"{option}: {error}") from None
    return len(data)

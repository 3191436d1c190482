"""Run the ASAM Quality Checker bundles for OpenSCENARIO XML and OpenDRIVE on exported files.

The checkers live in a venv of their own, `<test venv>/asam-qc`, made by scripts/install-test-deps.sh:
asam-qc-opendrive 1.0.0 (its only release) pins numpy<2, which cannot share an environment with vrusim's
NumPy 2 without leaving `pip check` failing. `check_files` runs this file with that venv's Python, once for
a whole list of files; there it calls each bundle's `run_checks` in-process (the packages' console scripts do
the same checks through a configuration and a result XML per file) and prints the results as JSON.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

CHECKER_VENV = Path(sys.prefix) / "asam-qc"
ERROR_STATUS = "error"
"""A checker's status when it crashed instead of completing or being skipped."""


def checker_python() -> Path:
    """The Python of the checkers' venv; a clear failure when scripts/install-test-deps.sh has not made it."""
    python = CHECKER_VENV / ("Scripts/python.exe" if sys.platform == "win32" else "bin/python")
    if not python.exists():
        raise RuntimeError(f"no ASAM Quality Checker venv at {CHECKER_VENV}: run scripts/install-test-deps.sh")
    return python


def check_files(paths: list[Path]) -> dict[Path, tuple[list[str], dict[str, str]]]:
    """For each .xosc / .xodr file: (issues as 'checker: LEVEL: description', status per checker)."""
    done = subprocess.run(
        [str(checker_python()), __file__, *map(str, paths)], capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise RuntimeError(f"the ASAM Quality Checkers failed:\n{done.stderr}")
    results = json.loads(done.stdout)
    return {path: (results[str(path)]["issues"], results[str(path)]["status"]) for path in paths}


def checker_errors(status: dict[str, str]) -> list[str]:
    """Checkers that crashed (status error) instead of completing or being skipped."""
    return [checker for checker, value in status.items() if value == ERROR_STATUS]


def _run_checks(path: Path) -> dict[str, object]:
    """In the checkers' venv: one file through its bundle."""
    import logging

    from qc_baselib import Configuration, Result
    from qc_baselib.models.common import IssueSeverity

    if path.suffix == ".xosc":
        from qc_openscenario import constants
        from qc_openscenario.main import run_checks
    else:
        from qc_opendrive import constants
        from qc_opendrive.main import run_checks
    config = Configuration()
    config.set_config_param("InputFile", str(path))
    result = Result()
    result.register_checker_bundle(
        name=constants.BUNDLE_NAME, description="", version=constants.BUNDLE_VERSION, summary=""
    )
    result.set_result_version(version=constants.BUNDLE_VERSION)
    previous = logging.root.manager.disable
    logging.disable(logging.INFO)  # the bundles log every check at INFO
    try:
        run_checks(config, result)
    finally:
        logging.disable(previous)
    issues, status = [], {}
    for bundle in result.get_checker_bundle_results():
        for checker in bundle.checkers:
            status[checker.checker_id] = checker.status.value
            for issue in checker.issues:
                where = "; ".join(location.description for location in issue.locations)
                issues.append(f"{checker.checker_id}: {IssueSeverity(issue.level).name}: {where}")
    return {"issues": issues, "status": status}


if __name__ == "__main__":
    print(json.dumps({name: _run_checks(Path(name)) for name in sys.argv[1:]}))

"""Run the ASAM Quality Checker bundles for OpenSCENARIO XML and OpenDRIVE in-process, one file at a time.

The packages' console scripts read a configuration XML and write a result XML per file; calling their
`run_checks` directly does the same checks without the files and the process start (~20 ms per file).
"""

from __future__ import annotations

import logging
from pathlib import Path

from qc_baselib import Configuration, Result
from qc_baselib.models.common import IssueSeverity
from qc_baselib.models.result import StatusType


def check_file(path: Path) -> tuple[list[str], dict[str, str]]:
    """(issues as 'checker: LEVEL: description', status per checker) of one .xosc or .xodr file."""
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
    return issues, status


def checker_errors(status: dict[str, str]) -> list[str]:
    """Checkers that crashed (status error) instead of completing or being skipped."""
    return [checker for checker, value in status.items() if value == StatusType.ERROR.value]

"""Read YAML scenario files into validated `Scenario` objects, with errors that name the field."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import ValidationError

from vrusim.errors import UserInputError
from vrusim.scenario.schema import Scenario
from vrusim.scenario.strict import error_message
from vrusim.scenario.yaml_file import read_yaml_file


def field_path(location: tuple[int | str, ...]) -> str:
    """Render a pydantic error location as a dotted path, e.g. `vrus[0].top_speed_mps`."""
    text = ""
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text or "(top level)"


def describe_validation_error(error: ValidationError, source: str) -> str:
    """One readable message listing every offending field and what was expected."""
    lines = [f"{source}: invalid scenario"]
    for item in error.errors(include_url=False):
        location = tuple(p for p in item["loc"] if p not in ("function-after[_from_pair(), Point]",))
        lines.append(f"  {field_path(location)}: {error_message(item)}")
    return "\n".join(lines)


def scenario_from_mapping(data: Any, source: str = "scenario") -> Scenario:
    """Validate a mapping (parsed YAML) into a Scenario, raising UserInputError on bad input."""
    if not isinstance(data, dict):
        raise UserInputError(f"{source}: expected a mapping of scenario fields at the top level")
    try:
        return Scenario.model_validate(data)
    except ValidationError as error:
        raise UserInputError(describe_validation_error(error, source)) from None


def load_scenario(path: str | Path) -> Scenario:
    """Load and validate a scenario YAML file."""
    path = Path(path)
    return scenario_from_mapping(read_yaml_file(path, "scenario"), str(path))

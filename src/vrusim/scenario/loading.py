"""Read YAML scenario files into validated `Scenario` objects, with errors that name the field."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import ValidationError

from vrusim.errors import UserInputError
from vrusim.scenario.field_paths import describe_validation_error, field_path
from vrusim.scenario.schema import Scenario
from vrusim.scenario.yaml_file import read_yaml_file

__all__ = ["describe_validation_error", "field_path", "load_scenario", "scenario_from_mapping"]


def scenario_from_mapping(data: Any, source: str = "scenario") -> Scenario:
    """Validate a mapping (parsed YAML) into a Scenario, raising UserInputError on bad input."""
    if not isinstance(data, dict):
        raise UserInputError(f"{source}: expected a mapping of scenario fields at the top level")
    sections = Scenario.model_fields
    if data and not any(isinstance(key, str) and key in sections for key in data):
        raise UserInputError(
            f"{source}: not a scenario file (its top level names none of the sections {', '.join(sections)})"
        )
    try:
        return Scenario.model_validate(data)
    except ValidationError as error:
        raise UserInputError(describe_validation_error(error, source)) from None


def load_scenario(path: str | Path) -> Scenario:
    """Load and validate a scenario YAML file."""
    path = Path(path)
    return scenario_from_mapping(read_yaml_file(path, "scenario"), str(path))

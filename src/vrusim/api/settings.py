"""Checks of the API's keyword arguments, and the API's names in messages that lower layers word for the CLI.

What `planner=`, `v2x=` and `seed=` do to a scenario: `vrusim.scenario.settings`.
"""

from __future__ import annotations

from collections.abc import Mapping

from vrusim.errors import UserInputError
from vrusim.planners.registry import make_planner
from vrusim.scenario.settings import V2X_OFF, V2X_ON


def renamed(error: UserInputError, names: Mapping[str, str]) -> UserInputError:
    """The error with the option names of a lower layer's message (`--scenario:`) replaced by the API's."""
    text = str(error)
    for old, new in names.items():
        text = text.replace(old, new)
    return UserInputError(text)


def check_planner(name: str, argument: str = "planner") -> str:
    """`name` if it names a planner (built-in, `module:Class` or entry point); else a UserInputError."""
    if not isinstance(name, str):
        raise UserInputError(f"{argument}: expected a planner name, e.g. 'fsm', 'aeb', got {name!r}")
    try:
        make_planner(name)
    except UserInputError as error:
        raise renamed(error, {"planner.name:": f"{argument}:"}) from None
    return name


def v2x_switch(setting: bool | str, argument: str = "v2x") -> bool:
    """On (True) or off (False) from True / "on" / False / "off"; anything else is a UserInputError."""
    if setting in (True, V2X_ON):
        return True
    if setting in (False, V2X_OFF):
        return False
    raise UserInputError(f"{argument}: expected on or off (True or False), got {setting!r}")

"""What the API's keyword arguments do to a scenario: planner, V2X setting and seed, applied as validated changes.

Each becomes dotted-path changes (`Scenario.replace`): `planner="aeb"` sets `planner` (the scenario's own
`planner.params` belong to its own planner, so another planner runs with its defaults, as `vrusim compare`
does); `v2x=` "on" / True switches V2X on as the scenario configures it, "off" / False off, a channel profile
name (`vrusim.scenario.v2x.V2X_PROFILES`) or an inline channel specification switches it on with that channel;
`seed=` sets `sim.seed`. A bad value is a UserInputError naming the argument.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from vrusim.errors import UserInputError
from vrusim.planners.registry import make_planner
from vrusim.scenario.field_paths import replaced
from vrusim.scenario.schema import Scenario
from vrusim.scenario.v2x import V2X_PROFILES, ChannelSpec

V2X_ON, V2X_OFF = "on", "off"
V2XSetting = bool | str | Mapping[str, Any] | ChannelSpec
"""A V2X setting: True / "on", False / "off", a channel profile name, or a channel specification."""


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


def v2x_changes(setting: V2XSetting, argument: str = "v2x") -> dict[str, Any]:
    """The dotted-path changes a V2X setting stands for."""
    if setting is True or setting == V2X_ON:
        return {"v2x.enabled": True}
    if setting is False or setting == V2X_OFF:
        return {"v2x.enabled": False}
    if isinstance(setting, Mapping | ChannelSpec) or (isinstance(setting, str) and setting in V2X_PROFILES):
        return {"v2x.enabled": True, "v2x.channel": setting}
    expected = ", ".join([V2X_ON, V2X_OFF, *V2X_PROFILES])
    raise UserInputError(f"{argument}: unknown V2X setting {setting!r}; expected one of: {expected}, or a channel spec")


def v2x_switch(setting: bool | str, argument: str = "v2x") -> bool:
    """On (True) or off (False) from True / "on" / False / "off"; anything else is a UserInputError."""
    if setting in (True, V2X_ON):
        return True
    if setting in (False, V2X_OFF):
        return False
    raise UserInputError(f"{argument}: expected on or off (True or False), got {setting!r}")


def configured(
    scenario: Scenario, planner: str | None = None, v2x: V2XSetting | None = None, seed: int | None = None
) -> Scenario:
    """The scenario with the planner, V2X setting and seed that are given (None: as the scenario has it)."""
    changes: dict[str, Any] = {}
    if planner is not None and planner != scenario.planner.name:
        changes["planner"] = {"name": planner, "params": {}}
    if v2x is not None:
        changes.update(v2x_changes(v2x))
    if seed is not None:
        changes["sim.seed"] = seed
    if not changes:
        return scenario
    return replaced(scenario, changes, f"{scenario.name} with {_arguments(planner, v2x, seed)}")


def _arguments(planner: str | None, v2x: V2XSetting | None, seed: int | None) -> str:
    given = {"planner": planner, "v2x": v2x, "seed": seed}
    return ", ".join(f"{name}={value!r}" for name, value in given.items() if value is not None)

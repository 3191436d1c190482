"""Run settings users give beside a scenario — planner, V2X setting, seed — as validated dotted-path changes.

`planner="aeb"` sets `planner` (the scenario's own `planner.params` belong to its own planner, so another
planner runs with its defaults, as `vrusim compare` does); the V2X setting "on" / True switches V2X on as the
scenario configures it, "off" / False off, a channel profile name (`V2X_PROFILES`) or an inline channel
specification switches it on with that channel; `seed` sets `sim.seed`. Used by `vrusim.run`; the same
meaning as the command line's `--v2x`, `--planner` and `--seed`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from vrusim.errors import UserInputError
from vrusim.scenario.field_paths import replaced
from vrusim.scenario.schema import Scenario
from vrusim.scenario.v2x import V2X_PROFILES, ChannelSpec

V2X_ON, V2X_OFF = "on", "off"
V2XSetting = bool | str | Mapping[str, Any] | ChannelSpec
"""A V2X setting: True / "on", False / "off", a channel profile name, or a channel specification."""


def v2x_changes(setting: V2XSetting, argument: str = "v2x") -> dict[str, Any]:
    """The dotted-path changes a V2X setting stands for; an unknown setting is a UserInputError naming
    `argument`."""
    if setting is True or setting == V2X_ON:
        return {"v2x.enabled": True}
    if setting is False or setting == V2X_OFF:
        return {"v2x.enabled": False}
    if isinstance(setting, Mapping | ChannelSpec) or (isinstance(setting, str) and setting in V2X_PROFILES):
        return {"v2x.enabled": True, "v2x.channel": setting}
    expected = ", ".join([V2X_ON, V2X_OFF, *V2X_PROFILES])
    raise UserInputError(f"{argument}: unknown V2X setting {setting!r}; expected one of: {expected}, or a channel spec")


def with_settings(
    scenario: Scenario, planner: str | None = None, v2x: V2XSetting | None = None, seed: int | None = None
) -> Scenario:
    """The scenario with the planner, V2X setting and seed that are given (None: as the scenario has it),
    validated; a refused value is a UserInputError naming the scenario, the settings and the field."""
    changes: dict[str, Any] = {}
    if planner is not None and planner != scenario.planner.name:
        changes["planner"] = {"name": planner, "params": {}}
    if v2x is not None:
        changes.update(v2x_changes(v2x))
    if seed is not None:
        changes["sim.seed"] = seed
    if not changes:
        return scenario
    given = {"planner": planner, "v2x": v2x, "seed": seed}
    label = ", ".join(f"{name}={value!r}" for name, value in given.items() if value is not None)
    return replaced(scenario, changes, f"{scenario.name} with {label}")

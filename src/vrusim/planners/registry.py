"""Find a planner by name: built-ins (`fsm`, `none`) or any class given as `module:Class`."""

from __future__ import annotations

import importlib
from collections.abc import Callable

from vrusim.errors import UserInputError
from vrusim.planners.base import HoldSpeedPlanner, Planner
from vrusim.planners.fsm import FsmPlanner

BUILTIN_PLANNERS: dict[str, Callable[[], Planner]] = {"fsm": FsmPlanner, "none": HoldSpeedPlanner}


def make_planner(name: str) -> Planner:
    """A new planner instance for `name` (a built-in name or `package.module:ClassName`)."""
    if name in BUILTIN_PLANNERS:
        return BUILTIN_PLANNERS[name]()
    if ":" not in name:
        known = ", ".join(sorted(BUILTIN_PLANNERS))
        raise UserInputError(f"planner.name: unknown planner {name!r}; expected one of {known} or module:Class")
    module_name, _, class_name = name.partition(":")
    try:
        cls = getattr(importlib.import_module(module_name), class_name)
    except Exception as error:  # any failure to import a user's module is a bad name or a broken plug-in
        raise UserInputError(f"planner.name: cannot import {name!r} ({error.__class__.__name__}: {error})") from None
    if not isinstance(cls, type):
        raise UserInputError(f"planner.name: {name!r} is not a class")
    try:
        planner = cls()
    except Exception as error:
        raise UserInputError(f"planner.name: cannot create {name!r} without arguments ({error})") from None
    if not isinstance(planner, Planner):
        raise UserInputError(f"planner.name: {name!r} has no reset(params) and act(observation) methods")
    return planner

"""Find a planner by name: a built-in, a class given as `module:Class`, or one registered as an entry point.

Look-up order for `planner.name`: the built-ins (`fsm`, `none`, `aeb`, `predictive`, and the low-speed reference
functions `acpe`, `reverse_aeb`, `dow`; they cannot be shadowed),
then `package.module:ClassName`, then the entry points of group `vrusim.planners` that installed distributions
declare, e.g. in their pyproject.toml:

    [project.entry-points."vrusim.planners"]
    brake-on-detection = "mypkg.brake_on_detection:BrakeOnDetection"

Entry points are trusted: the user installed them. A `module:Class` name comes from a scenario file, which is
data people exchange, so it is imported only when the user allows it outside that file: `vrusim
--allow-module-planners ...`, the environment variable VRUSIM_ALLOW_MODULE_PLANNERS=1, or
`allow_module_planners()` in Python. Without it the name is refused before anything is imported.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.metadata
from collections.abc import Callable
from pathlib import Path

from vrusim.errors import UserInputError
from vrusim.planners.aeb import AebPlanner
from vrusim.planners.base import HoldSpeedPlanner, Planner
from vrusim.planners.fsm import FsmPlanner
from vrusim.planners.permission import (  # noqa: F401 (re-exported: the public home of these names)
    MODULE_PLANNERS_ENV,
    MODULE_PLANNERS_FLAG,
    allow_module_planners,
    module_planners_allowed,
)
from vrusim.planners.predictive import PredictivePlanner


def _imported(module: str, name: str) -> Callable[[], Planner]:
    """The class `name` of `module`, imported when first instantiated: the low-speed reference functions, which
    only low-speed tests and scenarios name, stay out of every other command's start."""

    def make() -> Planner:
        return getattr(importlib.import_module(module), name)()

    make.__name__ = make.__qualname__ = name
    return make


BUILTIN_PLANNERS: dict[str, Callable[[], Planner]] = {
    "fsm": FsmPlanner,
    "none": HoldSpeedPlanner,
    "aeb": AebPlanner,
    "predictive": PredictivePlanner,
    "acpe": _imported("vrusim.planners.acpe", "AcpePlanner"),
    "reverse_aeb": _imported("vrusim.planners.reverse_aeb", "ReverseAebPlanner"),
    "dow": _imported("vrusim.planners.dow", "DowPlanner"),
}
ENTRY_POINT_GROUP = "vrusim.planners"


def _check_module_allowed(name: str) -> None:
    """Refuse a `module:Class` name, before importing anything, unless the user allowed module planners."""
    if not module_planners_allowed():
        raise UserInputError(
            f"planner.name: {name!r} names Python code, which vrusim imports only when you allow it outside the "
            f"scenario file: pass {MODULE_PLANNERS_FLAG} (vrusim {MODULE_PLANNERS_FLAG} run ...) or set "
            f"{MODULE_PLANNERS_ENV}=1; installed planners (entry points) need neither"
        )


def registered_planners() -> dict[str, importlib.metadata.EntryPoint]:
    """Planners that installed distributions register under the `vrusim.planners` entry-point group, by name."""
    found: dict[str, importlib.metadata.EntryPoint] = {}
    for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        if entry.name in found and found[entry.name].value != entry.value:
            raise UserInputError(
                f"planner.name: entry point {entry.name!r} of group {ENTRY_POINT_GROUP!r} is registered twice, "
                f"as {found[entry.name].value!r} and {entry.value!r}"
            )
        found[entry.name] = entry
    return found


def make_planner(name: str) -> Planner:
    """A new planner instance for `name` (a built-in name, `package.module:ClassName` or an entry-point name)."""
    if name in BUILTIN_PLANNERS:
        return BUILTIN_PLANNERS[name]()
    if ":" in name:
        _check_module_allowed(name)
        return _instantiate(_import_class(name), repr(name))
    registered = registered_planners()
    if name in registered:
        entry = registered[name]
        where = f"{name!r} (entry point {entry.value!r})"
        try:
            cls = entry.load()
        except Exception as error:  # a broken plug-in is the user's input, not our bug
            raise UserInputError(f"planner.name: cannot load {where} ({error.__class__.__name__}: {error})") from None
        return _instantiate(cls, where)
    known = ", ".join([*BUILTIN_PLANNERS, *sorted(registered)])
    raise UserInputError(
        f"planner.name: unknown planner {name!r}; expected one of {known}, module:Class, or a name registered "
        f"under the {ENTRY_POINT_GROUP!r} entry-point group"
    )


def _import_class(name: str) -> object:
    module_name, _, class_name = name.partition(":")
    try:
        return getattr(importlib.import_module(module_name), class_name)
    except Exception as error:  # any failure to import a user's module is a bad name or a broken plug-in
        raise UserInputError(f"planner.name: cannot import {name!r} ({error.__class__.__name__}: {error})") from None


def _instantiate(cls: object, where: str) -> Planner:
    if not isinstance(cls, type):
        raise UserInputError(f"planner.name: {where} is not a class")
    try:
        planner = cls()
    except Exception as error:
        raise UserInputError(f"planner.name: cannot create {where} without arguments ({error})") from None
    if not isinstance(planner, Planner):
        raise UserInputError(f"planner.name: {where} has no reset(params) and act(observation) methods")
    return planner


def plugin_source(name: str) -> dict[str, str | None] | None:
    """Which code a plug-in planner runs: its module, the module file and that file's SHA-256 (None for a
    built-in, whose code vrusim's own source digest covers). Entry points add their distribution and version.

    Only the module that defines the class is hashed: a change in another module of the plug-in goes unseen.
    """
    if name in BUILTIN_PLANNERS:
        return None
    info: dict[str, str | None] = {"planner": name}
    target = name
    if ":" in name:
        _check_module_allowed(name)
    else:
        entry = registered_planners().get(name)
        if entry is None:
            make_planner(name)  # raises the unknown-planner error
            return None  # pragma: no cover (make_planner raised)
        target = entry.value
        dist = getattr(entry, "dist", None)
        info["distribution"] = None if dist is None else f"{dist.name} {dist.version}"
    module_name = target.partition(":")[0].strip()
    try:
        module = importlib.import_module(module_name)
    except Exception as error:  # a broken plug-in is the user's input, not our bug
        raise UserInputError(f"planner.name: cannot import {name!r} ({error.__class__.__name__}: {error})") from None
    file = getattr(module, "__file__", None)
    info["module"] = module_name
    info["file"] = file
    info["sha256"] = hashlib.sha256(Path(file).read_bytes()).hexdigest() if file else None
    return info

"""Keep only some variants of a running batch: the engine drops variants that have stopped from its working set.

A stopped variant's results are final, yet stepping it costs as much as stepping a running one. One generic
`take(obj, index)` compacts every per-variant object: arrays, dataclasses (every field), named tuples and
lists (one item per variant); stateful parts of the engine (planner, channel, sensor model) call
`take_members(self, index)` from their `compact(index)`, which does the same to every attribute. Nothing is
listed by hand, so a new field or attribute is compacted without being registered anywhere. Arrays lead with
the variant axis; a class names the exceptions in `variant_axes` (name → axis) and the members that are
not per variant (shared tables) in `shared`. Taken arrays are C-contiguous copies of the same dtype, so the
compiled kernels see the same array types.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

_CONSTANTS = (int, float, bool, str, np.generic, type(None))


def _take_array(array: np.ndarray, index: np.ndarray, axis: int = 0) -> np.ndarray:
    return np.ascontiguousarray(np.take(array, index, axis=axis))


def _member(owner: object, name: str, value: Any, index: np.ndarray) -> Any:
    if name in getattr(owner, "shared", ()):
        return value
    if isinstance(value, np.ndarray):
        return _take_array(value, index, getattr(owner, "variant_axes", {}).get(name, 0))
    return take(value, index)


def _check_sizes(owner: object, old: dict[str, Any], index: np.ndarray) -> None:
    """Every array taken from `owner` must have the same number of variants: a table shared by all variants
    that is not declared in `shared` would otherwise be cut silently."""
    axes, shared = getattr(owner, "variant_axes", {}), getattr(owner, "shared", ())
    sizes = {
        name: value.shape[axes.get(name, 0)]
        for name, value in old.items()
        if isinstance(value, np.ndarray) and name not in shared and value.ndim > axes.get(name, 0)
    }
    if len(set(sizes.values())) > 1:
        raise ValueError(
            f"{type(owner).__name__}: per-variant arrays of different lengths {sizes}; declare tables that are not "
            "per variant in `shared` and other variant axes in `variant_axes`"
        )


def take(obj: Any, index: np.ndarray) -> Any:
    """The variants `index` of `obj` (a new object; constants and None as they are)."""
    if isinstance(obj, np.ndarray):
        return _take_array(obj, index)
    if isinstance(obj, _CONSTANTS):
        return obj
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        values = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj) if f.init}
        _check_sizes(obj, values, index)
        return dataclasses.replace(obj, **{name: _member(obj, name, v, index) for name, v in values.items()})
    if isinstance(obj, tuple) and hasattr(obj, "_fields"):  # a named tuple of per-variant arrays
        return type(obj)(*(take(value, index) for value in obj))
    if isinstance(obj, list):
        return [obj[i] for i in np.asarray(index).tolist()]
    raise TypeError(f"take: cannot compact a {type(obj).__name__}; declare it in its owner's `shared`")


def take_members(owner: object, index: np.ndarray) -> None:
    """Keep variants `index` in every attribute of `owner` (in place): what a component's `compact` does."""
    members = dict(vars(owner))
    _check_sizes(owner, members, index)
    for name, value in members.items():
        setattr(owner, name, _member(owner, name, value, index))


def compactable(*parts: object) -> bool:
    """Whether every part can drop variants: its own class defines `compact(index)`.

    An inherited `compact` does not count: a subclass may keep per-variant state its base does not know.
    """
    return all(callable(vars(type(part)).get("compact")) for part in parts)

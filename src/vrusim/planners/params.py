"""Planner parameters from YAML `planner.params` (`BatchParams.planner_params`, plain mappings): validated per
variant when the planner packs them at `reset`, errors naming the scenario and the field."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from pydantic import BaseModel, ValidationError

from vrusim.errors import UserInputError
from vrusim.scenario.loading import field_path
from vrusim.scenario.strict import error_message
from vrusim.sim.params import BatchParams

Model = TypeVar("Model", bound=BaseModel)


def validate_params(model: type[Model], params: BatchParams) -> list[Model]:
    """Each variant's `planner.params` validated by `model`; the first error names the scenario and the field.

    Message: `<scenario>: planner.params.<field>: <reason>` ("unknown field" for a name the model lacks).
    Equal mappings are validated once and share one model (a sweep's variants mostly repeat the base's).
    """
    out: list[Model] = []
    seen: dict[object, Model] = {}
    by_identity: dict[int, Model] = {}  # the same mapping object again (`take` repeats a sweep base's): no key built
    for name, given in zip(params.names, params.planner_params, strict=True):
        found = by_identity.get(id(given))
        if found is None:
            key = _content_key(given)
            found = seen.get(key) if key is not None else None
            if found is None:
                found = _validated(model, name, given)
                if key is not None:
                    seen[key] = found
            by_identity[id(given)] = found
        out.append(found)
    return out


def _validated(model: type[Model], name: str, given) -> Model:
    """`given` validated by `model`, or the UserInputError naming scenario `name` and the field."""
    try:
        return model.model_validate(dict(given))
    except ValidationError as error:
        item = error.errors(include_url=False)[0]
        where = field_path(("planner", "params", *item["loc"]))
        raise UserInputError(f"{name}: {where}: {error_message(item)}") from None


def _content_key(given) -> object | None:
    """A hashable key equal only for mappings of equal names, value types and values; None when a value is not
    hashable (such mappings are validated once per mapping object)."""
    try:
        key = frozenset((name, type(value), value) for name, value in given.items())
        hash(key)
    except TypeError:
        return None
    return key


def param_table(per_variant: Sequence[BaseModel], names: Sequence[str]) -> np.ndarray:
    """Numeric parameters as a [B, len(names)] float table for compiled kernels (column j = names[j]).

    Each distinct model (by identity: `validate_params` shares one among equal mappings) is read once.
    """
    row_of: dict[int, int] = {}
    rows = np.array([row_of.setdefault(id(p), len(row_of)) for p in per_variant], dtype=np.intp)
    models = list({id(p): p for p in per_variant}.values())  # in order of first appearance, as `row_of`
    table = np.array([[float(getattr(p, name)) for name in names] for p in models], dtype=float)
    return table.reshape(len(models), len(names))[rows]

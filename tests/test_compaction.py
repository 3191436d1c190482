"""The generic `take`: every field and attribute is compacted without being listed anywhere."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from vrusim.sim.compaction import take, take_members

KEEP = np.array([0, 2])


@dataclass
class State:
    speed: np.ndarray
    brand_new_field: np.ndarray  # never registered anywhere
    history: np.ndarray  # [D, B]
    table: np.ndarray  # shared by all variants
    names: list
    maybe: np.ndarray | None = None
    dt_s: float = 0.1

    variant_axes: ClassVar[dict[str, int]] = {"history": 1}
    shared: ClassVar[frozenset[str]] = frozenset({"table"})


def test_a_new_dataclass_field_is_compacted_without_registration():
    state = State(np.arange(3.0), np.array([7, 8, 9]), np.arange(6).reshape(2, 3), np.arange(10), ["a", "b", "c"])
    kept = take(state, KEEP)
    assert kept.speed.tolist() == [0.0, 2.0]
    assert kept.brand_new_field.tolist() == [7, 9]
    assert kept.history.tolist() == [[0, 2], [3, 5]] and kept.history.flags.c_contiguous
    assert kept.table.tolist() == list(range(10))
    assert kept.names == ["a", "c"] and kept.maybe is None and kept.dt_s == 0.1


class Component:
    def __init__(self) -> None:
        self.mode = np.array([1, 2, 3], dtype=np.int8)

    def compact(self, index: np.ndarray) -> None:
        take_members(self, index)


def test_a_new_component_attribute_is_compacted_without_registration():
    component = Component()
    component.added_later = np.array([[1.0], [2.0], [3.0]])
    component.compact(KEEP)
    assert component.mode.tolist() == [1, 3] and component.mode.dtype == np.int8
    assert component.added_later.tolist() == [[1.0], [3.0]]


def test_an_undeclared_shared_table_is_refused_not_cut():
    component = Component()
    component.table = np.arange(10)
    with pytest.raises(ValueError, match="different lengths"):
        component.compact(KEEP)

"""Planner parameter tables: each distinct model read once, the same table as reading every variant's model."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vrusim.planners.fsm import PARAM_ORDER, FsmParams
from vrusim.planners.params import param_table, validate_params
from vrusim.scenario.loading import scenario_from_mapping
from vrusim.sim.compaction import take
from vrusim.sim.params import pack

MODELS = [FsmParams(), FsmParams(headway_s=3.0), FsmParams(headway_s=3.0, pre_slow_decel_mps2=1.0), FsmParams()]
"""Distinct objects; the first and last, and no others, are equal."""


def _every_row(per_variant, names) -> np.ndarray:
    """The table read model by model, without sharing."""
    return np.array([[float(getattr(p, name)) for name in names] for p in per_variant]).reshape(-1, len(names))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, len(MODELS) - 1), max_size=40))
def test_param_table_equals_reading_every_variant(picks):
    per_variant = [MODELS[i] for i in picks]
    table = param_table(per_variant, PARAM_ORDER)
    assert table.shape == (len(picks), len(PARAM_ORDER)) and table.dtype == float
    assert np.array_equal(table, _every_row(per_variant, PARAM_ORDER))


def _scenario(name: str, **params) -> object:
    return scenario_from_mapping(
        {
            "name": name,
            "ego": {"start": {"x_m": -50, "y_m": -1.75}, "cruise_speed_mps": 10.0},
            "planner": {"name": "fsm", "params": params},
            "vrus": [{"type": "pedestrian", "start": {"x_m": 10, "y_m": -8}, "heading_deg": 90}],
        }
    )


def test_validate_params_shares_a_model_among_rows_of_one_mapping():
    """A sweep's variants repeat their base's mapping object (`take`); rows of one mapping share one model, and
    the table has each variant's own values."""
    batch = pack([_scenario("a", headway_s=3.0), _scenario("b", headway_s=2.5)])
    rows = np.array([0, 0, 1, 1, 0])
    variants = take(batch, rows)
    models = validate_params(FsmParams, variants)
    assert models[0] is models[1] is models[4] and models[2] is models[3]
    assert [m.headway_s for m in models] == [3.0, 3.0, 2.5, 2.5, 3.0]
    table = param_table(models, PARAM_ORDER)
    assert np.array_equal(table[:, PARAM_ORDER.index("headway_s")], [3.0, 3.0, 2.5, 2.5, 3.0])
    assert np.array_equal(table, _every_row(models, PARAM_ORDER))

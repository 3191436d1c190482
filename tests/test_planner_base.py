"""The planner attributes the engine reads (`mode_names`, `mode`, `warning`): declared with defaults on
`PlannerBase`, read through one helper, so plug-ins with and without them, subclassing or not, all run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vrusim.engine.simulate import simulate
from vrusim.planners.aeb import AebPlanner
from vrusim.planners.base import (
    HoldSpeedPlanner,
    PlannerBase,
    planner_mode,
    planner_mode_names,
    planner_warning,
)
from vrusim.planners.fsm import FsmPlanner
from vrusim.planners.predictive import PredictivePlanner

BRAKE_AT_S = 1.0


class Bare:
    """A plug-in with only `reset` and `act` (no base class, no optional attributes)."""

    def reset(self, params) -> None:
        self.size = params.size

    def act(self, observation):
        return np.zeros(self.size)


class Full:
    """A plug-in that declares every optional attribute itself, without subclassing."""

    mode_names = ("cruise", "brake")

    def reset(self, params) -> None:
        self.mode = np.zeros(params.size, dtype=np.int8)
        self.warning = np.zeros(params.size, dtype=bool)

    def act(self, observation):
        late = observation.t_s >= BRAKE_AT_S - 1e-9
        self.mode = np.full(self.mode.shape, 1 if late else 0, dtype=np.int8)
        self.warning = np.full(self.mode.shape, late)
        return np.where(self.mode == 1, -2.0, 0.0)


class Sub(PlannerBase):
    """A subclass that sets none of the optional attributes."""

    def reset(self, params) -> None:
        self.size = params.size

    def act(self, observation):
        return np.zeros(self.size)


@pytest.fixture
def scenario(make_scenario):
    return make_scenario({"sim": {"duration_s": 3.0}})


@pytest.mark.parametrize("planner", [Bare(), Sub()], ids=["bare", "subclass"])
def test_a_planner_without_the_attributes_gets_the_declared_defaults(scenario, planner):
    run = simulate([scenario], planner=planner)
    assert run.mode_names == ("running",) == PlannerBase.mode_names
    assert planner_mode(planner) is None and planner_warning(planner) is None
    assert run.metrics.transitions == []
    assert math.isnan(run.metrics.first_warning_s[0])
    traced = simulate([scenario], planner=type(planner)(), trace=True)
    assert (traced.trace["planner_mode"] == 0).all()


def test_a_planner_with_the_attributes_has_them_read_without_subclassing(scenario):
    planner = Full()
    run = simulate([scenario], planner=planner)
    assert planner_mode_names(planner) == run.mode_names == ("cruise", "brake")
    assert [(round(t, 6), v, old, new) for t, v, old, new in run.metrics.transitions] == [(BRAKE_AT_S, 0, 0, 1)]
    assert run.metrics.first_warning_s[0] == pytest.approx(BRAKE_AT_S)
    assert planner_warning(planner) is planner.warning


def test_the_built_ins_subclass_the_base_and_only_the_aeb_warns():
    for cls in (HoldSpeedPlanner, FsmPlanner, AebPlanner, PredictivePlanner):
        assert issubclass(cls, PlannerBase)
        assert planner_mode_names(cls()) == cls.mode_names != PlannerBase.mode_names
    assert planner_warning(FsmPlanner()) is None


def test_the_engine_and_ncap_read_the_attributes_only_through_the_helpers():
    from pathlib import Path

    import vrusim

    src = Path(vrusim.__file__).parent
    for module in ("engine/simulate.py", "ncap/grid.py"):
        text = (src / module).read_text()
        for name in ("mode", "mode_names", "warning"):
            assert f'"{name}"' not in text, (module, name)

"""FSM defect of issue 17: a VRU is tracked until it is clear of the ego's swept footprint, not its front bumper."""

from __future__ import annotations

from vrusim.engine.simulate import simulate
from vrusim.metrics.summary import summary_rows
from vrusim.paper.cases import scenario_dir
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.schema import Scenario


def _flank_case(emergency_decel_mps2: float) -> dict:
    """The paper's pedestrian case, V2X off, with a weaker emergency brake."""
    data = load_scenario(scenario_dir() / "pedestrian_crossing.yaml").with_v2x(False).model_dump()
    data["planner"]["params"]["emergency_decel_mps2"] = emergency_decel_mps2
    return summary_rows(simulate([Scenario.model_validate(data)]))[0]


def test_fsm_keeps_braking_for_a_pedestrian_beside_the_flank():
    """With 3 m/s² the front bumper passes the pedestrian's station at 4.64 s while she walks on into the flank.

    Before the fix the FSM dropped her there, returned to Cruise and accelerated into her (contact at 5.006 s,
    10.55 m/s). Now it holds Emergency-Brake: the only transition is Cruise → Emergency-Brake at 3.06 s, and the
    ego is slower at the (still unavoidable) contact.
    """
    row = _flank_case(3.0)
    assert [(t["from"], t["to"]) for t in row["transitions"]] == [("cruise", "emergency_brake")]
    assert abs(row["transitions"][0]["t_s"] - 3.06) < 1e-9
    assert row["collided"]
    # braking at 3 m/s² from 15 m/s from about 3.16 s (lag, jerk limit) leaves at most 15 - 3 * 1.75 = 9.75 m/s
    assert row["impact_ego_speed_mps"] < 9.75


def test_fsm_flank_fix_keeps_the_paper_impact():
    """The paper's own setting (6 m/s²) still collides at 5.03 s (Fig. 6c), never back in Cruise before."""
    row = _flank_case(6.0)
    assert row["collided"]
    assert abs(row["contact_time_s"] - 5.03) < 0.01
    assert all(t["to"] != "cruise" for t in row["transitions"])

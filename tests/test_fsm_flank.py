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


def test_conflict_tracker_keeps_a_vru_beside_the_flank_until_it_is_behind_the_rear_bumper(make_scenario):
    """ConflictTracker (for NumPy planners) applies the same rule. Rear axle at station 10 m of a straight route
    (4.5 m ego, rear overhang 0.9 m: front bumper 3.6 m ahead of it, rear bumper 0.9 m behind); a VRU of radius
    r = 0.3 m on the centre line conflicts while its far edge is at or ahead of the rear bumper."""
    import numpy as np

    from vrusim.planners.conflict import ConflictTracker
    from vrusim.sim.observation import Observation
    from vrusim.sim.params import pack

    scenario = make_scenario(
        {"vrus": [{"type": "pedestrian", "start": [50.0, 10.0], "heading_deg": 90.0, "radius_m": 0.3}]}
    )
    params = pack([scenario])
    ones = np.ones(1)

    def conflict_at(vru_x: float) -> bool:
        """Whether a VRU `vru_x` m ahead of the rear axle (negative: behind) conflicts."""
        station = np.array([10.0])
        x, y, hx, hy, _ = params.routes.locate(params.route_offset, station)
        estimate = np.zeros((7, 1, 1))
        estimate[0], estimate[1] = x[0] + vru_x * hx[0], y[0] + vru_x * hy[0]
        obs = Observation(
            0.0, 0.01, x, y, hx, hy, np.zeros(1), np.zeros(1), station, params.cruise_speed_mps,
            params.rear_to_front_m, params.half_width_m, 2.0 * params.half_length_m, params.routes,
            params.route_offset, np.ones((1, 1), dtype=bool), np.ones((1, 1), dtype=np.int8), estimate,
            params.vru_radius_m,
        )  # fmt: skip
        tracker = ConflictTracker(horizon_s=5.0 * ones, margin_m=0.0 * ones, memory_s=0.0 * ones)
        return bool(tracker.analyse(obs).conflict[0, 0])

    assert conflict_at(2.0)  # beside the flank: behind the front bumper, ahead of the rear one
    assert conflict_at(-1.15)  # far edge -0.85 m: still just ahead of the rear bumper
    assert not conflict_at(-1.25)  # far edge -0.95 m: clear of the swept footprint

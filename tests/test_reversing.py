"""A reversing ego (Euro NCAP CPRA): distance travelled, body footprint, rear sensor, braking and contact,
against analytic expectations; and the reverse-needs-a-straight-route validation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from vrusim.cli.app import app
from vrusim.engine.simulate import simulate
from vrusim.errors import UserInputError
from vrusim.scenario.loading import load_scenario
from vrusim.scenario.routes import ego_route_spec
from vrusim.sim.params import pack
from vrusim.sim.sensing.sector import sense
from vrusim.sim.state import initial_ego, initial_vrus

LENGTH, WIDTH, WHEELBASE, REAR_OVERHANG = 4.6, 1.8, 2.7, 1.1  # front overhang 0.8 m: the mirror is visible
START = (10.0, -1.75)


class ConstantCommandPlanner:
    """Commands a fixed acceleration per variant (m/s^2) at every step."""

    def __init__(self, commands):
        self.commands = np.asarray(commands, dtype=float)

    def reset(self, params) -> None:
        assert params.size == self.commands.size

    def act(self, observation) -> np.ndarray:
        return self.commands.copy()


def reversing(make_scenario, heading_deg: float = 0.0, speed_mps: float = 8 / 3.6, **changes):
    ego = {
        "start": {"x_m": START[0], "y_m": START[1], "heading_deg": heading_deg},
        "cruise_speed_mps": speed_mps,
        "reverse": True,
        "route": {"kind": "straight", "length_m": 50.0},
        "length_m": LENGTH,
        "width_m": WIDTH,
        "wheelbase_m": WHEELBASE,
        "rear_overhang_m": REAR_OVERHANG,
        "max_decel_mps2": 10.0,
    }
    return make_scenario({"name": f"reverse-{heading_deg}", "ego": ego, **changes})


def body(heading_deg: float) -> tuple[float, float]:
    h = math.radians(heading_deg)
    return math.cos(h), math.sin(h)


def corners(cx, cy, hx, hy):
    """The four corners of the ego rectangle, sorted (the set of points it spans)."""
    pts = [
        (cx + a * LENGTH / 2 * hx - b * WIDTH / 2 * hy, cy + a * LENGTH / 2 * hy + b * WIDTH / 2 * hx)
        for a in (-1, 1)
        for b in (-1, 1)
    ]
    return np.array(sorted(pts))


@pytest.mark.parametrize("heading_deg", [0.0, 90.0, -135.0])
def test_reversing_covers_v_t_backwards(make_scenario, heading_deg):
    v = 8 / 3.6
    scenario = reversing(make_scenario, heading_deg, v, sim={"duration_s": 4.0})
    trace = simulate([scenario], trace=True).trace
    bx, by = body(heading_deg)
    t = trace["t_s"]
    # the rectangle centre moves along the route, against the heading the body faces, at constant speed
    assert np.allclose(trace["ego_x_m"][:, 0], START[0] - v * t * bx, atol=1e-9)
    assert np.allclose(trace["ego_y_m"][:, 0], START[1] - v * t * by, atol=1e-9)
    assert np.all(trace["ego_speed_mps"][:, 0] == pytest.approx(v))
    assert trace["ego_station_m"][-1, 0] == pytest.approx(v * t[-1], abs=1e-9)
    # the traced heading is the direction of travel, opposite to the body
    assert np.allclose(trace["ego_heading_x"][:, 0], -bx, atol=1e-12)
    assert np.allclose(trace["ego_heading_y"][:, 0], -by, atol=1e-12)
    # at every step the rectangle spans the same world area as the body facing heading_deg at that centre
    for i in range(0, len(t), 37):
        cx, cy = trace["ego_x_m"][i, 0], trace["ego_y_m"][i, 0]
        simulated = corners(cx, cy, trace["ego_heading_x"][i, 0], trace["ego_heading_y"][i, 0])
        real = corners(START[0] - v * t[i] * bx, START[1] - v * t[i] * by, bx, by)
        assert np.allclose(simulated, real, atol=1e-9)


def test_packed_geometry_is_the_mirrored_body(make_scenario):
    scenario = reversing(make_scenario, 30.0)
    params = pack([scenario])
    front_overhang = LENGTH - WHEELBASE - REAR_OVERHANG
    # the simulation's rear axle is the real front axle; its "front" bumper is the real rear bumper
    assert params.rear_to_centre_m[0] == pytest.approx(LENGTH / 2 - front_overhang)
    assert params.rear_to_front_m[0] == pytest.approx(LENGTH - front_overhang)
    bx, by = body(30.0)
    spec = ego_route_spec(scenario.ego)
    real_front_axle = (START[0] + (LENGTH / 2 - front_overhang) * bx, START[1] + (LENGTH / 2 - front_overhang) * by)
    assert (spec.x0_m, spec.y0_m) == pytest.approx(real_front_axle)
    assert math.degrees(spec.heading0_rad) == pytest.approx(210.0)


def test_sensor_apex_at_the_real_rear_bumper_looking_back(make_scenario):
    heading = 60.0
    bx, by = body(heading)
    rear = (START[0] - LENGTH / 2 * bx, START[1] - LENGTH / 2 * by)
    front = (START[0] + LENGTH / 2 * bx, START[1] + LENGTH / 2 * by)
    pedestrians = [
        {"type": "pedestrian", "start": [rear[0] - 5 * bx, rear[1] - 5 * by], "heading_deg": 0.0},  # behind
        {"type": "pedestrian", "start": [front[0] + 5 * bx, front[1] + 5 * by], "heading_deg": 0.0},  # ahead
    ]
    scenario = reversing(make_scenario, heading, vrus=pedestrians, sensor={"range_m": 10.0, "fov_deg": 90.0})
    params = pack([scenario])
    ego = initial_ego(params)
    assert (ego.front_x_m[0], ego.front_y_m[0]) == pytest.approx(rear, abs=1e-12)
    assert (ego.heading_x[0], ego.heading_y[0]) == pytest.approx((-bx, -by), abs=1e-12)
    assert (ego.centre_x_m[0], ego.centre_y_m[0]) == pytest.approx(START, abs=1e-12)
    seen = sense(params, ego.front_x_m, ego.front_y_m, ego, initial_vrus(params))
    assert seen[0].tolist() == [True, False]


@settings(max_examples=25, deadline=None)
@given(kph=st.sampled_from([4.0, 8.0]), decel=st.floats(1.0, 9.0), heading=st.floats(-180.0, 180.0))
def test_reversing_stopping_distance(make_scenario, kph, decel, heading):
    v0 = kph / 3.6
    scenario = reversing(make_scenario, heading, v0, sim={"duration_s": v0 / decel + 0.5})
    trace = simulate([scenario], planner=ConstantCommandPlanner([-decel]), trace=True).trace
    assert trace["ego_speed_mps"][-1, 0] == 0.0
    bx, by = body(heading)
    dx, dy = trace["ego_x_m"][-1, 0] - START[0], trace["ego_y_m"][-1, 0] - START[1]
    assert -(dx * bx + dy * by) == pytest.approx(v0 * v0 / (2 * decel), rel=0.01)  # backwards
    assert abs(dx * by - dy * bx) < 1e-9  # no sideways drift


def test_reversing_into_a_pedestrian_behind(make_scenario):
    """Contact when the real rear bumper reaches the footprint: gap / speed; reported on the simulated front."""
    v, gap = 8 / 3.6, 3.0
    pedestrian = {"type": "pedestrian", "start": [START[0] - LENGTH / 2 - gap, START[1]], "heading_deg": 90.0}
    pedestrian["trigger"] = {"at_time_s": 1e6}
    scenario = reversing(make_scenario, 0.0, v, vrus=[pedestrian], sim={"duration_s": 5.0})
    metrics = simulate([scenario]).metrics
    assert metrics.collided[0]
    assert metrics.contact_time_s[0] == pytest.approx((gap - 0.5) / v, abs=0.011)
    assert metrics.impact_local_x_m[0] == pytest.approx(LENGTH / 2, abs=1e-6)  # "front" = real rear bumper
    assert metrics.impact_local_y_m[0] == pytest.approx(0.0, abs=1e-6)


def test_overlap_check_for_a_reversing_ego(make_scenario):
    touching = {"type": "pedestrian", "start": [START[0] - LENGTH / 2 - 0.4, START[1]], "heading_deg": 90.0}
    with pytest.raises(UserInputError, match=r"vrus\[0\] starts overlapping the ego"):
        reversing(make_scenario, vrus=[touching])


REVERSE_LEFT = """\
name: reverse-left
ego:
  start: {x_m: 0, y_m: 0, heading_deg: 0}
  cruise_speed_mps: 2.2
  reverse: true
  route: {kind: left, radius_m: 9.0, length_m: 40}
vrus:
  - {type: pedestrian, start: [-10, 0], heading_deg: 90}
"""


def test_reverse_needs_a_straight_route(tmp_path):
    path = tmp_path / "reverse_left.yaml"
    path.write_text(REVERSE_LEFT, encoding="utf-8")
    with pytest.raises(UserInputError) as info:
        load_scenario(path)
    assert str(info.value) == (
        f"{path}: invalid scenario\n  ego.reverse: reversing needs a straight route (route.kind is 'left')"
    )
    result = CliRunner().invoke(app, ["run", str(path)], catch_exceptions=False)
    assert result.exit_code == 2, result.output
    assert "ego.reverse" in result.output
    assert "Traceback" not in result.output

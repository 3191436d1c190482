"""Gym rendering: `render_mode="human"` (one pyplot window, updated in place) and `rgb_array`, headless on Agg."""

from __future__ import annotations

import time
import warnings

import gymnasium
import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from matplotlib.colors import to_rgba
from matplotlib.patches import Polygon

import vrusim.gym  # noqa: F401  (registers the ids)
from vrusim.gym import VruEnv, VruVectorEnv
from vrusim.gym.render import FRAME_DPI, FRAME_WIDTH_IN
from vrusim.scenario.schema import Scenario
from vrusim.viz.scene import scene_figure
from vrusim.viz.style import EGO_FACE


@pytest.fixture(autouse=True)
def agg_backend():
    """Headless: pyplot on the non-interactive Agg backend; no figure left behind."""
    matplotlib.use("Agg")
    plt.close("all")
    yield
    plt.close("all")


def _hold() -> np.ndarray:
    return np.array([0.0], dtype=np.float32)


def _ego_patch(figure) -> Polygon:
    (ego,) = [p for p in figure.axes[0].patches if isinstance(p, Polygon) and p.get_facecolor() == to_rgba(EGO_FACE)]
    return ego


def _ego_centre_m(env: VruEnv) -> np.ndarray:
    """The ego's centre, m, from the planner's observation (rear axle + heading × axle-to-centre distance)."""
    obs = env.planner_observation
    ahead = float(obs.rear_to_front_m[0] - obs.ego_length_m[0] / 2)
    heading = np.array([obs.ego_heading_x[0], obs.ego_heading_y[0]])
    return np.array([obs.ego_x_m[0], obs.ego_y_m[0]]) + ahead * heading


def _with_dt(source: str, dt_s: float) -> Scenario:
    data = VruEnv(source).scenario.model_dump()
    data["sim"]["dt_s"] = dt_s
    return Scenario.model_validate(data)


def test_metadata_declares_human_and_a_real_time_fps():
    assert VruEnv.metadata["render_modes"] == ["human", "rgb_array"]
    assert VruEnv("paper:pedestrian").metadata["render_fps"] == pytest.approx(100.0)  # 1 / (0.01 s a step)
    assert VruEnv(_with_dt("paper:pedestrian", 0.05)).metadata["render_fps"] == pytest.approx(20.0)
    assert VruEnv.metadata["render_fps"] == 100  # the class keeps the default for every instance


def test_human_mode_draws_one_figure_updated_in_place():
    env = gymnasium.make("vrusim/PaperPedestrian-v0", render_mode="human").unwrapped
    assert env.figure is None and plt.get_fignums() == []  # created lazily
    env.reset(seed=0)
    figure = env.figure
    assert plt.get_fignums() == [figure.number]
    ego = _ego_patch(figure)
    assert np.allclose(ego.get_xy()[:4].mean(axis=0), _ego_centre_m(env))
    assert env.render() is None
    label = figure.axes[0].texts[-1]
    for _ in range(60):
        _, _, _, _, info = env.step(_hold())
        assert env.figure is figure and _ego_patch(figure) is ego  # the same window and artists, moved
        assert np.allclose(ego.get_xy()[:4].mean(axis=0), _ego_centre_m(env))
        assert label.get_text().startswith(f"t = {info['t_s']:.2f} s")
        assert env.render() is None
    assert info["t_s"] == pytest.approx(60 * env.scenario.sim.dt_s)
    assert plt.get_fignums() == [figure.number] and len(figure.axes) == 1 and len(figure.legends) == 1
    x0, x1 = figure.axes[0].get_xlim()
    assert x0 < _ego_centre_m(env)[0] < x1  # the view follows the ego
    env.reset(seed=0)  # a new episode reuses the window
    assert env.figure is figure and np.allclose(ego.get_xy()[:4].mean(axis=0), _ego_centre_m(env))
    env.close()
    assert env.figure is None and plt.get_fignums() == []
    env.close()  # twice is fine


def test_human_mode_survives_the_user_closing_the_window():
    env = VruEnv("paper:escooter", render_mode="human")
    env.reset()
    env.step(_hold())
    plt.close(env.figure)  # what closing the window does
    for _ in range(5):
        env.step(_hold())  # no crash, no window popping up again in this episode
    assert env.figure is None and plt.get_fignums() == []
    env.reset()  # the next episode opens a new window
    assert plt.get_fignums() == [env.figure.number]
    assert np.allclose(_ego_patch(env.figure).get_xy()[:4].mean(axis=0), _ego_centre_m(env))
    env.close()
    assert plt.get_fignums() == []


def test_human_mode_follows_an_episode_through_an_impact():
    env = VruEnv(_with_dt("paper:escooter", 0.1), render_mode="human")  # 42 steps to the impact
    env.reset()
    terminated = truncated = False
    while not (terminated or truncated):
        _, _, terminated, truncated, info = env.step(np.array([2.0], dtype=np.float32))
    assert info["metrics"]["collided"]
    (impact,) = [line for line in env.figure.axes[0].lines if line.get_marker() == "*"]
    assert len(impact.get_xdata()) == 1  # the impact star
    (legend,) = env.figure.legends
    assert "impact" in [text.get_text() for text in legend.get_texts()]  # the legend was rebuilt in place
    assert len(plt.get_fignums()) == 1
    env.close()


def test_human_mode_is_paced_to_render_fps():
    env = VruEnv(_with_dt("paper:pedestrian", 0.05), render_mode="human")  # 20 frames/s
    env.reset()
    start = time.perf_counter()
    for _ in range(10):
        env.step(_hold())
    assert time.perf_counter() - start >= 10 * 0.05 * 0.95  # the 10 steps' frames cannot come sooner
    env.close()


def test_check_env_passes_with_every_render_mode():
    for mode in ("human", "rgb_array"):
        env = gymnasium.make("vrusim/PaperEscooter-v0", render_mode=mode)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # advice only: "use a symmetric, normalised Box" (ours is in m/s^2)
            check_env(env.unwrapped)  # also makes and checks an env of every declared mode (the spec)
        env.close()
    assert plt.get_fignums() == []


def _fresh_frame(env: VruEnv) -> np.ndarray:
    """The current state drawn on a new figure, as `render()` did before the figure was kept between frames."""
    frames = env._frames
    recording = frames.recording(env._episodes.stepper.run())
    figure = scene_figure(recording, float(recording.t_s[-1]), FRAME_WIDTH_IN, FRAME_DPI, frames.window)
    figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba())[:, :, :3].copy()


def test_rgb_array_frames_are_those_of_a_fresh_figure():
    """Frames drawn in place have exactly the pixels of the scene drawn anew, through the impact (which adds a
    legend entry and the star) and into a second episode."""
    env = VruEnv("paper:escooter", render_mode="rgb_array")
    env.reset()
    first = env.render()
    figure = env.figure
    assert np.array_equal(first, _fresh_frame(env))
    terminated = truncated = False
    step = 0
    while not (terminated or truncated):
        _, _, terminated, truncated, info = env.step(np.array([2.0], dtype=np.float32))
        step += 1
        if step % 150 == 0 or terminated:
            assert np.array_equal(env.render(), _fresh_frame(env)), step
    assert info["metrics"]["collided"]
    env.reset()
    assert np.array_equal(env.render(), first)
    assert env.figure is figure and plt.get_fignums() == []  # one figure; rgb_array never touches pyplot
    env.close()
    assert env.figure is None


@pytest.mark.parametrize("mode", ["Human", "rgb", "ansi", ""])
def test_a_bad_render_mode_names_the_option_and_the_accepted_values(mode):
    with pytest.raises(ValueError, match=r"render_mode: .* expected one of None, 'human', 'rgb_array'"):
        VruEnv("paper:pedestrian", render_mode=mode)


def test_the_vector_env_names_the_option_when_asked_to_render():
    with pytest.raises(ValueError, match=r"render_mode: 'human' is not supported; expected None"):
        VruVectorEnv(2, render_mode="human")

"""`render_mode="rgb_array"`: the running episode as vrusim's bird's-eye scene (vrusim.viz.scene).

The episode's states are recorded as the engine records a trace (one row per step, the reset state first);
a frame draws the latest one. The view follows the ego in a window of fixed size, so every frame of an episode
has the same pixel size (as video recorders need).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from vrusim.engine.simulate import BatchRun, TraceRecorder
from vrusim.engine.stepper import BatchStepper
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.schema import Scenario
from vrusim.viz.recording import Recording, ego_route_xy_m, key_events, vru_paths_xy_m
from vrusim.viz.scene import ViewWindow, scene_figure

FRAME_WIDTH_M = 60.0
"""Width of the world window a frame shows, m (height: half of it)."""
FRAME_WIDTH_IN, FRAME_DPI = 8.0, 80.0
"""Frame size: inches × dots per inch = pixels."""


def frame_window(scenario: Scenario, margin_m: float = 10.0) -> ViewWindow:
    """A window of FRAME_WIDTH_M × FRAME_WIDTH_M / 2 following the ego inside the planned paths' extent."""
    xy = np.concatenate([ego_route_xy_m(scenario), *vru_paths_xy_m(scenario)])
    box = (
        float(xy[:, 0].min()) - margin_m,
        float(xy[:, 0].max()) + margin_m,
        float(xy[:, 1].min()) - margin_m,
        float(xy[:, 1].max()) + margin_m,
    )
    return ViewWindow(box, FRAME_WIDTH_M, FRAME_WIDTH_M / 2, follow=True)


class EpisodeFrames:
    """Records one episode's states (batch of one) and draws them on request."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.window = frame_window(scenario)
        self.recorder = TraceRecorder()

    def restart(self, stepper: BatchStepper) -> None:
        """A new episode: record its initial state (call after the first `observe()`)."""
        self.recorder = TraceRecorder()
        self.recorder.add(stepper, None, np.zeros(1))

    def add(self, stepper: BatchStepper, command: np.ndarray) -> None:
        """Record the state after a step under `command` (m/s^2)."""
        self.recorder.add(stepper, None, command)

    def frame(self, run: BatchRun) -> np.ndarray:
        """RGB image (uint8 [H, W, 3]) of the latest recorded state."""
        rows = self.recorder.finish()
        trace = {name: values[:, 0] if values.ndim > 1 else values for name, values in rows.items()}
        row = summary_rows(run)[0]
        recording = Recording(self.scenario, trace, row, run.mode_names, key_events(row, trace))
        figure = scene_figure(recording, float(trace["t_s"][-1]), FRAME_WIDTH_IN, FRAME_DPI, self.window)
        return _pixels(figure)


def _pixels(figure: Figure) -> np.ndarray:
    canvas = figure.canvas
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()

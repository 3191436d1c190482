"""Rendering of the running episode as vrusim's bird's-eye scene (vrusim.viz.scene), in two outputs of one drawing.

The episode's states are recorded as the engine records a trace (one row per step, the reset state first); a
frame draws the latest one. The view follows the ego in a window of fixed size. `EpisodeFrames` draws on one
figure, built on the first frame (road, paths, legend) and updated in place (`viz.scene.ScenePanel`):

- `render_mode="rgb_array"`: an Agg figure read back as pixels, every frame of an episode the same pixel size (as
  video recorders need);
- `render_mode="human"` (`HumanWindow`): a pyplot figure window (the user's matplotlib backend), redrawn by
  `reset()` and `step()` and paced to `render_fps` as `plt.pause` does. pyplot is imported only here, only then.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from vrusim.engine.simulate import BatchRun, TraceRecorder
from vrusim.engine.stepper import BatchStepper
from vrusim.metrics.summary import summary_rows
from vrusim.scenario.schema import Scenario
from vrusim.viz.literal_text import literal_texts, quiet_text
from vrusim.viz.recording import Recording, ego_route_xy_m, key_events, vru_paths_xy_m
from vrusim.viz.scene import ScenePanel, ViewWindow, scene_figure_size_in

FRAME_WIDTH_M = 60.0
"""Width of the world window a frame shows, m (height: half of it)."""
FRAME_WIDTH_IN, FRAME_DPI = 8.0, 80.0
"""Frame size: inches × dots per inch = pixels (rgb_array; a human window opens at the same size in inches)."""
MIN_PAUSE_S = 0.001
"""Shortest pause after a human-mode frame, s: the GUI event loop runs at least this long (as `plt.pause`)."""


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


def agg_figure(size_in: tuple[float, float]) -> Figure:
    """An off-screen figure (Agg canvas, no pyplot state) of `size_in` inches at FRAME_DPI."""
    figure = Figure(figsize=size_in, dpi=FRAME_DPI, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


class EpisodeFrames:
    """Records one episode's states (batch of one) and draws the latest on one figure, updated in place."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.window = frame_window(scenario)
        self.size_in = scene_figure_size_in(FRAME_WIDTH_IN, self.window)
        """Figure size, inches (width, height)."""
        self.recorder = TraceRecorder()
        self.panel: ScenePanel | None = None
        """The scene on the current figure (None until the first frame, and after `forget_figure`)."""

    @property
    def started(self) -> bool:
        """An episode has been reset (its initial state is recorded)."""
        return bool(self.recorder.rows)

    def restart(self, stepper: BatchStepper) -> None:
        """A new episode: record its initial state (call after the first `observe()`)."""
        self.recorder = TraceRecorder()
        self.recorder.add(stepper, None, np.zeros(1))

    def add(self, stepper: BatchStepper, command: np.ndarray) -> None:
        """Record the state after a step under `command` (m/s^2)."""
        self.recorder.add(stepper, None, command)

    def recording(self, run: BatchRun) -> Recording:
        """The episode so far as a `Recording` (its trace ends at the latest state)."""
        rows = self.recorder.finish()
        trace = {name: values[:, 0] if values.ndim > 1 else values for name, values in rows.items()}
        row = summary_rows(run)[0]
        return Recording(self.scenario, trace, row, run.mode_names, key_events(row, trace))

    def draw(self, run: BatchRun, new_figure: Callable[[tuple[float, float]], Figure]) -> Figure:
        """Draw the latest state: on the current figure, or first on `new_figure(size_in)` (an empty figure with
        a constrained layout). The drawing of both render modes; returns the figure (its canvas not yet drawn)."""
        recording = self.recording(run)
        if self.panel is None:
            self.panel = ScenePanel(new_figure(self.size_in), recording, self.window)
        self.panel.show(recording, float(recording.t_s[-1]))
        return literal_texts(self.panel.figure)

    def forget_figure(self) -> None:
        """Draw on a new figure next time."""
        self.panel = None

    def frame(self, run: BatchRun) -> np.ndarray:
        """RGB image (uint8 [H, W, 3]) of the latest recorded state (rgb_array)."""
        canvas = self.draw(run, agg_figure).canvas
        with quiet_text():
            canvas.draw()
        return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


class HumanWindow:
    """render_mode="human": the episode in one pyplot figure window, opened on the first frame and redrawn in place.

    After each frame the GUI event loop runs until 1 / `fps` s have passed since the previous frame (at least
    MIN_PAUSE_S), which is what `plt.pause` does, but on this figure (it need not be pyplot's current one, and is not
    raised above other windows at every frame). With a non-interactive backend (Agg) nothing is shown and the pause
    is a sleep. A window the user closes stays closed for the rest of the episode (steps go on without drawing);
    the next `reset()` opens a new one.
    """

    def __init__(self, frames: EpisodeFrames, fps: float) -> None:
        self.frames = frames
        self.period_s = 1.0 / fps
        """Time between frames, s (wall clock)."""
        self.figure: Figure | None = None
        """The window's figure (None before the first frame, after the user closed it, and after `close`)."""
        self._last_frame_s = -np.inf
        self._closed_by_user = False

    def show(self, run: BatchRun, new_episode: bool = False) -> None:
        """Draw the latest state (`new_episode`: the episode was reset, so reopen a window the user closed)."""
        import matplotlib.pyplot as plt

        if self.figure is not None and not plt.fignum_exists(self.figure.number):  # the user closed it
            self.close()
            self._closed_by_user = True
        if self._closed_by_user and not new_episode:
            return
        self._closed_by_user = False
        self.figure = self.frames.draw(run, self._open)
        canvas = self.figure.canvas
        canvas.draw_idle()
        wait_s = self.period_s - (time.perf_counter() - self._last_frame_s)
        canvas.start_event_loop(min(max(wait_s, MIN_PAUSE_S), self.period_s))
        self._last_frame_s = time.perf_counter()

    @staticmethod
    def _open(size_in: tuple[float, float]) -> Figure:
        import matplotlib.pyplot as plt

        figure = plt.figure(figsize=size_in, layout="constrained")
        figure.canvas.manager.set_window_title("vrusim")
        plt.show(block=False)
        return figure

    def close(self) -> None:
        """Close the window (if open)."""
        if self.figure is not None:
            import matplotlib.pyplot as plt

            plt.close(self.figure)
            self.figure = None
        self.frames.forget_figure()

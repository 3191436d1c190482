"""GIF and MP4 animations of a recording: the scene redrawn per frame from the Agg canvas buffer.

The artists are built once (`SceneArtists`) and moved per frame; the layout is computed once. GIF frames are
quantised to one shared 256-colour palette with Pillow; MP4 is H.264 through the ffmpeg binary that
imageio-ffmpeg ships (the 'video' extra; nothing is downloaded). The file is written atomically: a temporary
file next to the target, renamed over it only when complete.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar
from PIL import Image

from vrusim.extras import extra
from vrusim.io.atomic import write_atomically
from vrusim.limits import check_limit
from vrusim.viz import style
from vrusim.viz.figure_io import check_output_path
from vrusim.viz.literal_text import drawing, quiet_text
from vrusim.viz.recording import Recording
from vrusim.viz.scene import SceneArtists, legend_handles, view_window
from vrusim.viz.style import recording_labels

ANIMATION_SUFFIXES = (".gif", ".mp4")
"""File types `write_animation` writes, chosen by suffix."""


def check_animation_path(path: str | Path) -> Path:
    """The path if an animation can be written there (.gif or .mp4, existing writable folder; for .mp4 the
    'video' extra installed); else a UserInputError saying why. Cheap: call it before simulating."""
    path = check_output_path(path, ANIMATION_SUFFIXES, "animation")
    if path.suffix.lower() == ".mp4":
        _imageio_ffmpeg()
    return path


def frame_count(duration_s: float, fps: float = 25.0, speed: float = 1.0) -> int:
    """Frames of an animation of `duration_s` (s) of simulated time: round(duration × fps / speed), at least 2."""
    if fps <= 0 or speed <= 0:
        raise ValueError("fps and speed must be positive")
    return max(2, round(duration_s * fps / speed))


def check_frame_budget(duration_s: float, fps: float = 25.0, speed: float = 1.0) -> None:
    """Refuse an animation beyond limit `animation_frames` (a GIF holds every frame in memory until it is
    written, about 0.8 MB a frame): cheap, so call it before simulating."""
    what = f"an animation of {duration_s:,.1f} s at {fps:g} frames/s (speed {speed:g})"
    check_limit("animation_frames", frame_count(duration_s, fps, speed), what)


def frame_times(recording: Recording, fps: float = 25.0, speed: float = 1.0) -> np.ndarray:
    """Times (s) of the frames: `frame_count` frames evenly from t = 0 to the end, so the last frame shows the
    final state (impact or route end). `speed` > 1 plays faster than real time."""
    duration = float(recording.t_s[-1])
    return np.linspace(0.0, duration, frame_count(duration, fps, speed))


def animation_figure(recording: Recording, width_in: float = 8.0, dpi: float = 100.0) -> tuple[Figure, SceneArtists]:
    """The figure an animation draws on (even pixel size, layout fixed) and its scene artists.

    No tick labels (their text layout would cost most of a frame): a scale bar gives the size instead.
    """
    window = view_window(recording)
    width_px = 2 * round(width_in * dpi / 2)
    height_in = width_in * window.height_m / window.width_m + 0.9
    height_px = 2 * round(height_in * dpi / 2)
    fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    scene = SceneArtists(ax, recording, window)
    ax.xaxis.set_visible(False)
    ax.yaxis.set_visible(False)
    bar_m = _scale_bar_m(window.width_m)
    ax.add_artist(
        AnchoredSizeBar(
            ax.transData,
            bar_m,
            f"{bar_m:g} m",
            "lower right",
            pad=0.3,
            borderpad=0.4,
            sep=2,
            frameon=False,
            fontproperties={"size": 7},
        )
    )
    label = recording_labels([recording])[0]
    ax.set_title(f"{recording.scenario.name} · {label}", fontsize=9, loc="left")
    handles, names = legend_handles([recording])
    fig.legend(handles, names, loc="outside lower center", ncol=min(len(handles), 5), fontsize=7, frameon=False)
    scene.update(0)
    with drawing(fig):
        fig.canvas.draw()
    fig.set_layout_engine("none")  # freeze the layout
    return fig, scene


def _scale_bar_m(width_m: float) -> float:
    """A round length near a sixth of the window width, m."""
    for length in (1, 2, 5, 10, 20, 50, 100, 200, 500):
        if length >= width_m / 6:
            return float(length)
    return 1000.0


def iter_frames(
    recording: Recording, fps: float = 25.0, width_in: float = 8.0, dpi: float = 100.0, speed: float = 1.0
) -> Iterator[np.ndarray]:
    """RGB frames (uint8 [H, W, 3]) at `frame_times`, read from the canvas buffer.

    What does not move is drawn once and restored per frame: with a fixed view everything but the moving
    artists (which are then drawn on top in z-order), with a following view everything but the scene axes
    (then redrawn whole, as its limits change).
    """
    fig, scene = animation_figure(recording, width_in, dpi)
    canvas, ax = fig.canvas, scene.ax
    moving = [ax] if scene.window.follow else scene.moving_artists()
    shown = [a.get_visible() for a in moving]
    for artist in moving:
        artist.set_visible(False)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for artist, visible in zip(moving, shown, strict=True):
        artist.set_visible(visible)
    renderer = canvas.get_renderer()
    for t in frame_times(recording, fps, speed):
        scene.update(recording.nearest_index(float(t)))
        canvas.restore_region(background)
        for artist in moving:
            if artist.get_visible():
                artist.draw(renderer)
        yield np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


def write_animation(
    recording: Recording,
    path: str | Path,
    fps: float = 25.0,
    width_in: float = 8.0,
    dpi: float = 100.0,
    speed: float = 1.0,
) -> Path:
    """Write `recording` as an animated GIF or an H.264 MP4 (by the suffix of `path`), atomically; return it.

    round(duration × fps / speed) frames, `width_in` × `dpi` pixels wide. Bad suffix or folder, or more frames than
    limit `animation_frames`: UserInputError.
    """
    path = check_animation_path(path)
    check_frame_budget(float(recording.t_s[-1]), fps, speed)
    frames = iter_frames(recording, fps, width_in, dpi, speed)
    write = _write_gif if path.suffix.lower() == ".gif" else _write_mp4
    with quiet_text():  # the frames are drawn while writing
        return write_atomically(path, lambda temp: write(frames, temp, fps), "animation")


def _write_gif(frames: Iterator[np.ndarray], temp: Path, fps: float) -> None:
    """Quantise every frame to one palette (from the first frame and the style's colours, so that the rings
    and the impact star that appear later keep their colours) and save a looping GIF."""
    first_frame = next(frames)
    source = np.concatenate([first_frame, _swatch(first_frame.shape[1])])
    palette = Image.fromarray(source).quantize(colors=255, method=Image.Quantize.FASTOCTREE)
    first = Image.fromarray(first_frame)
    images = [first.quantize(palette=palette, dither=Image.Dither.NONE)]
    images += [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    images[0].save(
        temp,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=round(1000 / fps),
        loop=0,
        optimize=False,
        disposal=1,
    )


def _swatch(width: int) -> np.ndarray:
    """A strip [16, width, 3] of every style colour (repeated), to put them in the GIF palette."""
    colours = [
        style.EGO_FACE,
        style.EGO_EDGE,
        style.V2X,
        style.IMPACT,
        style.DETECTED_SENSOR,
        style.OBSTACLE_FACE,
        *style.VRU_COLOURS.values(),
    ]
    rgb = (np.array([to_rgb(c) for c in colours]) * 255).round().astype(np.uint8)
    block = max(1, width // (4 * len(rgb)))
    strip = np.repeat(rgb, block, axis=0)
    strip = np.resize(strip, (width, 3))
    return np.repeat(strip[None, :, :], 16, axis=0)


def _imageio_ffmpeg() -> ModuleType:
    """imageio-ffmpeg (the 'video' extra), or a UserInputError naming the extra."""
    with extra("video"):
        import imageio_ffmpeg
    return imageio_ffmpeg


def _write_mp4(frames: Iterator[np.ndarray], temp: Path, fps: float) -> None:
    imageio_ffmpeg = _imageio_ffmpeg()
    first = next(frames)
    height, width = first.shape[:2]
    writer = imageio_ffmpeg.write_frames(
        str(temp),
        (width, height),
        fps=fps,
        codec="libx264",
        quality=7,
        macro_block_size=2,
        output_params=["-f", "mp4", "-movflags", "+faststart"],
    )
    writer.send(None)
    try:
        writer.send(first.tobytes())
        for frame in frames:
            writer.send(frame.tobytes())
    finally:
        writer.close()

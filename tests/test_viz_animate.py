"""GIF and MP4 animations: frame count = duration × fps, frame size, motion between frames, atomic writes, and
`vrusim run --animate` end to end."""

from __future__ import annotations

import dataclasses
import warnings

import imageio.v2 as imageio_v2
import imageio.v3 as iio
import numpy as np
import pytest

from cli_helpers import assert_user_error, invoke
from conftest import PAPER_DIR
from vrusim.errors import UserInputError
from vrusim.paper.cases import paper_scenarios
from vrusim.viz import animate
from vrusim.viz.animate import frame_times, write_animation
from vrusim.viz.recording import record

FPS = 8.0
WIDTH_IN, DPI = 3.0, 50.0  # 150 px wide: size does not matter here


@pytest.fixture(scope="module")
def pedestrian():
    """The paper's pedestrian case without V2X (about 5 s, ends in an impact)."""
    scenario = next(s for case, v2x, s in paper_scenarios() if case.key == "pedestrian" and not v2x)
    return record([scenario])[0]


def _expected_frames(rec, fps: float = FPS) -> int:
    return round(float(rec.t_s[-1]) * fps)


def test_frame_times_span_the_run(pedestrian):
    times = frame_times(pedestrian, fps=25.0)
    assert len(times) == _expected_frames(pedestrian, 25.0)
    assert times[0] == 0.0 and times[-1] == pytest.approx(pedestrian.t_s[-1])
    assert len(frame_times(pedestrian, fps=25.0, speed=2.0)) == round(pedestrian.t_s[-1] * 12.5)


def test_gif_frames(pedestrian, tmp_path):
    path = write_animation(pedestrian, tmp_path / "run.gif", fps=FPS, width_in=WIDTH_IN, dpi=DPI)
    frames = iio.imread(path, index=None)
    assert frames.shape[0] == _expected_frames(pedestrian)
    assert frames.shape[2] == round(WIDTH_IN * DPI)
    assert frames.shape[1] % 2 == 0
    assert not np.array_equal(frames[0], frames[-1])
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).mean() > 1.0
    duration_ms = iio.immeta(path, index=0).get("duration")
    assert duration_ms == pytest.approx(1000 / FPS, abs=10)
    assert [p.name for p in tmp_path.iterdir()] == ["run.gif"]


def test_mp4_frames(pedestrian, tmp_path):
    path = write_animation(pedestrian, tmp_path / "run.mp4", fps=FPS, width_in=WIDTH_IN, dpi=DPI)
    reader = imageio_v2.get_reader(path, format="FFMPEG")
    try:
        meta = reader.get_meta_data()
        frames = [frame for frame in reader]
    finally:
        reader.close()
    assert meta["fps"] == pytest.approx(FPS)
    assert meta["codec"] == "h264"
    assert len(frames) == _expected_frames(pedestrian)
    assert frames[0].shape[1] == round(WIDTH_IN * DPI)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).mean() > 1.0
    assert [p.name for p in tmp_path.iterdir()] == ["run.mp4"]


@pytest.mark.parametrize("name", ["run.avi", "run", "no/such/folder/run.gif"])
def test_bad_paths_are_user_errors_and_write_nothing(pedestrian, tmp_path, name):
    with pytest.raises(UserInputError):
        write_animation(pedestrian, tmp_path / name, fps=FPS, width_in=WIDTH_IN, dpi=DPI)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_a_failure_while_drawing_leaves_no_file(pedestrian, tmp_path, monkeypatch, suffix):
    target = tmp_path / f"run{suffix}"
    target.write_bytes(b"old")
    calls = {"n": 0}
    update = animate.SceneArtists.update

    def failing(self, index):
        calls["n"] += 1
        if calls["n"] > 5:
            raise RuntimeError("boom")
        update(self, index)

    monkeypatch.setattr(animate.SceneArtists, "update", failing)
    with pytest.raises(RuntimeError, match="boom"):
        write_animation(pedestrian, target, fps=FPS, width_in=WIDTH_IN, dpi=DPI)
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]


def test_run_animate_end_to_end(tmp_path):
    out = tmp_path / "run.gif"
    result = invoke("run", PAPER_DIR / "pedestrian_crossing.yaml", "--animate", out)
    assert result.exit_code == 0, result.output
    assert "Animation written" in result.output
    frames = iio.imread(out, index=None)
    row = [line for line in result.output.splitlines() if "Contact time" in line]
    assert row, result.output
    assert frames.shape[0] >= 100  # 25 fps over the ~5 s run


def test_frames_beyond_the_budget_are_refused_before_drawing(tmp_path, monkeypatch):
    """A 3,600 s run asked `--animate` for 90,000 frames, which a GIF holds in memory (about 0.8 MB each): the
    frame count is checked against `animation_frames` first, and nothing is written."""
    long = tmp_path / "long.yaml"
    long.write_text(
        "name: long\nego: {start: {x_m: -50.0, y_m: -1.75}, cruise_speed_mps: 0.0}\n"
        "vrus: [{type: pedestrian, start: [18.0, -10.0], heading_deg: 90, top_speed_mps: 0}]\n"
        "sim: {dt_s: 0.1, duration_s: 3600}\n"
    )
    result = invoke("run", long, "--animate", tmp_path / "long.gif")
    assert_user_error(result, "--animate: an animation of 3,600.0 s at 25 frames/s", "90,000 frames exceeds the limit")
    assert not list(tmp_path.glob("*.gif")) and not list(tmp_path.glob(".*"))
    monkeypatch.setenv("VRUSIM_LIMIT_ANIMATION_FRAMES", "30")  # the 5 s run at 8 frames/s: 40
    rec = record([next(s for case, v2x, s in paper_scenarios() if case.key == "pedestrian" and not v2x)])[0]
    with pytest.raises(UserInputError, match="40 frames exceeds the limit of 30"):
        write_animation(rec, tmp_path / "run.gif", fps=FPS)
    assert write_animation(rec, tmp_path / "run.gif", fps=FPS, speed=4.0).exists()  # 10 frames of a 5 s run


def test_a_dollar_or_a_missing_glyph_in_the_name_is_drawn_literally_and_quietly(pedestrian, tmp_path):
    rec = dataclasses.replace(pedestrian, scenario=pedestrian.scenario.replace(name="A$$B 🚗"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = write_animation(rec, tmp_path / "a.gif", fps=2.0, width_in=WIDTH_IN, dpi=DPI)
    assert path.stat().st_size > 0

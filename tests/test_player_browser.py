"""The scene player in headless Chromium (the set-up of test_report_browser.py): played, the ego is drawn where the
trace puts it (within a pixel, three times); the scrubber moves the charts' cursor and a click on a chart moves the
scrubber; layer toggles hide and show their layers; the comparison player draws every run; nothing is fetched."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

from cli_helpers import invoke
from test_report_browser import browser, open_report  # noqa: F401  (the module-scoped Chromium fixture)
from vrusim.sources import scenario_of
from vrusim.viz.recording import Recording, record

CASE = "paper:pedestrian"
"""V2X off: a 5 s run ending in an impact (short, so the browser tests stay fast)."""

EGO_JS = """(panel) => {
  const svg = document.querySelectorAll('#player svg.scene')[panel];
  const body = svg.querySelectorAll('rect.ego-body');
  const ctm = svg.getScreenCTM();  // viewBox px → screen px (border, scaling and letterboxing included)
  return {
    t: window.vrusimPlayer.players['player'].time(),
    bodies: [...body].map(b => { const r = b.getBoundingClientRect();
                                  return [r.left + r.width / 2, r.top + r.height / 2]; }),
    ctm: [ctm.a, ctm.b, ctm.c, ctm.d, ctm.e, ctm.f],
    scale: Number(svg.dataset.scalePxPerM), tx: Number(svg.dataset.txPx), ty: Number(svg.dataset.tyPx),
  };
}"""


@pytest.fixture(scope="module")
def recording() -> Recording:
    return record([scenario_of(CASE, False)])[0]


@pytest.fixture(scope="module")
def run_report(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("player") / "run.html"
    result = invoke("report", CASE, "--v2x", "off", "--out", out)
    assert result.exit_code == 0, result.output
    return out


def ready(browser, path: Path):  # noqa: F811
    page, problems = open_report(browser, path)
    page.wait_for_selector("div.player[data-ready='true']", timeout=10_000)
    return page, problems


def wait_for_time(page, t_s: float, timeout_s: float = 10.0) -> None:
    """Poll until the playing player reaches `t_s` (the page's CSP forbids the eval of wait_for_function)."""
    deadline = time.monotonic() + timeout_s
    while page.evaluate("window.vrusimPlayer.players['player'].time()") < t_s:
        assert time.monotonic() < deadline, f"the player did not reach {t_s} s"
        page.wait_for_timeout(20)


def ego_on_screen_px(page, recording: Recording, panel: int = 0, body: int = 0) -> tuple[float, float, float]:
    """(player time s, drawn minus expected screen px in x and in y): expected from the trace at that time through
    the transform the panel states."""
    drawn = page.evaluate(EGO_JS, panel)
    t = drawn["t"]
    trace = recording.trace
    x = float(np.interp(t, recording.t_s, trace["ego_x_m"]))
    y = float(np.interp(t, recording.t_s, trace["ego_y_m"]))
    a, b, c, d, e, f = drawn["ctm"]
    u, v = drawn["tx"] + drawn["scale"] * x, drawn["ty"] - drawn["scale"] * y  # the stated world → viewBox px
    expected = (a * u + c * v + e, b * u + d * v + f)
    dx, dy = (drawn["bodies"][body][k] - expected[k] for k in range(2))
    return t, dx, dy


def test_played_ego_is_drawn_where_the_trace_puts_it(browser, run_report, recording):  # noqa: F811
    page, problems = ready(browser, run_report)
    player = page.locator("#player")
    player.scroll_into_view_if_needed()
    player.locator("select.speed").select_option("2")
    times = []
    for _ in range(3):  # each pause at least 1.02 s of play after the last (a loaded machine overshoots a target)
        player.locator("button.play").click()
        wait_for_time(page, times[-1] + 1.02 if times else 0.3)
        player.locator("button.play").click()  # pause
        assert player.locator("button.play").get_attribute("aria-pressed") == "false"
        t, dx, dy = ego_on_screen_px(page, recording)
        times.append(t)
        assert abs(dx) <= 1.0 and abs(dy) <= 1.0, (t, dx, dy)
    assert times[0] >= 0.3 and times[1] > times[0] + 1.0 and times[2] > times[1] + 1.0
    x_m = float(np.interp(times[2], recording.t_s, recording.trace["ego_x_m"]))
    assert x_m > float(recording.trace["ego_x_m"][0]) + 30.0  # the ego did move across the panel
    follow = player.locator("input.follow")
    follow.check()
    page.evaluate("window.vrusimPlayer.players['player'].seek(3.3)")
    t, dx, dy = ego_on_screen_px(page, recording)
    assert t == pytest.approx(3.3) and abs(dx) <= 1.0 and abs(dy) <= 1.0
    assert problems == []


def test_scrubber_and_charts_share_the_time_cursor(browser, run_report):  # noqa: F811
    page, problems = ready(browser, run_report)
    chart = page.locator("#run-speed")
    spec = chart.evaluate("c => JSON.parse(c.querySelector('script.chart-data').textContent)")
    x0, x1, left, right = spec["x_map"]
    scrub = page.locator("#player input.scrub")
    scrub.evaluate("s => { s.value = '2.5'; s.dispatchEvent(new Event('input', {bubbles: true})); }")
    for chart_id in ("run-speed", "run-accel", "run-gap"):
        cross = page.locator(f"#{chart_id} .crosshair")
        assert cross.get_attribute("visibility") == "visible"
        assert float(cross.get_attribute("x1")) == pytest.approx(left + (2.5 - x0) / (x1 - x0) * (right - left))
    assert "t (s) = 2.50" in chart.locator(".readout").inner_text()
    chart.scroll_into_view_if_needed()
    box = chart.locator("svg").bounding_box()
    target_s = 4.0
    vb_width = chart.locator("svg").evaluate("s => s.viewBox.baseVal.width")
    x_px = box["x"] + (left + (target_s - x0) / (x1 - x0) * (right - left)) * box["width"] / vb_width
    page.mouse.click(x_px, box["y"] + box["height"] / 2)
    seconds_per_px = (x1 - x0) / (right - left) * vb_width / box["width"]
    assert float(scrub.input_value()) == pytest.approx(target_s, abs=seconds_per_px)
    assert page.evaluate("window.vrusimPlayer.players['player'].time()") == pytest.approx(target_s, abs=seconds_per_px)
    page.mouse.move(0, 0)  # leaving the chart puts its cursor back on the player's time
    cross = float(page.locator("#run-speed .crosshair").get_attribute("x1"))
    assert cross == pytest.approx(left + (float(scrub.input_value()) - x0) / (x1 - x0) * (right - left))
    assert problems == []


LAYER_JS = """(key) => [...document.querySelectorAll('#player g[data-layer="' + key + '"]')].map(g => {
  const r = g.getBoundingClientRect();
  return {display: getComputedStyle(g).display, area: r.width * r.height};
})"""


def test_layer_toggles_hide_and_show_their_layers(browser, run_report):  # noqa: F811
    page, problems = ready(browser, run_report)
    page.evaluate("window.vrusimPlayer.players['player'].seek(4.0)")
    drawn = ("road", "paths", "trails", "sensor", "vrus", "ego")
    for key in drawn:
        assert all(g["area"] > 0 and g["display"] != "none" for g in page.evaluate(LAYER_JS, key)), key
    for key in drawn:
        page.locator(f"#player .player-layers input[data-layer='{key}']").uncheck()
        hidden = page.evaluate(LAYER_JS, key)
        assert hidden and all(g["display"] == "none" and g["area"] == 0 for g in hidden), key
        others = [k for k in drawn if k != key]
        assert all(page.evaluate(LAYER_JS, k)[0]["area"] > 0 for k in others), key
        page.locator(f"#player .player-layers input[data-layer='{key}']").check()
        assert all(g["area"] > 0 for g in page.evaluate(LAYER_JS, key)), key
    page.evaluate("window.vrusimPlayer.players['player'].seek(5.03)")
    assert page.locator("#player polygon.impact").get_attribute("visibility") == "visible"
    page.evaluate("window.vrusimPlayer.players['player'].seek(1.0)")
    assert page.locator("#player polygon.impact").get_attribute("visibility") == "hidden"
    assert problems == []


def test_nothing_is_fetched(browser, run_report):  # noqa: F811
    page = browser.new_page()
    requests: list[str] = []
    page.route("**/*", lambda route: (requests.append(route.request.url), route.continue_()))
    page.on("request", lambda request: requests.append(request.url))
    page.goto(run_report.resolve().as_uri(), wait_until="load")
    page.wait_for_selector("div.player[data-ready='true']", timeout=10_000)
    page.locator("#player button.play").click()
    wait_for_time(page, 0.3)
    page.locator("#player button.play").click()
    page.locator("#player button.zoom-in").click()
    page.locator("#player input.follow").check()
    assert requests, "the page itself is a request"
    assert {url for url in requests if not url.startswith("data:")} == {run_report.resolve().as_uri()}
    page.close()


def test_comparison_player_draws_every_run(browser, tmp_path):  # noqa: F811
    out = tmp_path / "compare.html"
    result = invoke("compare", CASE, "--v2x", "off,on", "--report", out)
    assert result.exit_code == 0, result.output
    page, problems = ready(browser, out)
    recordings = record([scenario_of(CASE, False), scenario_of(CASE, True)])
    assert page.locator("#player svg.scene").count() == 2  # side by side
    page.evaluate("window.vrusimPlayer.players['player'].seek(3.0)")
    for panel, rec in enumerate(recordings):
        t, dx, dy = ego_on_screen_px(page, rec, panel)
        assert abs(dx) <= 1.0 and abs(dy) <= 1.0, (panel, dx, dy)
    assert page.locator("#player svg.scene").nth(1).locator("circle.rsu-comm").count() == 1
    page.locator("#player select.layout").select_option("overlay")
    assert page.locator("#player svg.scene").count() == 1
    page.evaluate("window.vrusimPlayer.players['player'].seek(4.5)")
    for body, rec in enumerate(recordings):
        t, dx, dy = ego_on_screen_px(page, rec, 0, body)
        assert math.isclose(t, 4.5) and abs(dx) <= 1.0 and abs(dy) <= 1.0, (body, dx, dy)
    page.locator("#player .player-layers input[data-layer='v2x']").uncheck()
    assert page.locator("#player g[data-layer='v2x']").evaluate("g => g.getBoundingClientRect().width") == 0
    assert problems == []


SECTOR_JS = """() => [...document.querySelectorAll('#player polygon.sector, #player polygon.shadow')].map(p =>
  (p.getAttribute('points') || '').trim().split(/\\s+/).filter(Boolean).map(xy => xy.split(',').map(Number)))"""


def test_sensor_sector_is_cut_where_the_figures_cut_it(browser, tmp_path):  # noqa: F811
    """A pedestrian behind parked cars (CPNCO): the drawn sector equals the figures' ray casting (every other ray
    of `viz.scene.visible_sector_xy`, 0.5° apart), and the occluded part is drawn as a shadow."""
    from vrusim.viz.scene import _box_frames, visible_sector_xy

    test_id = "2023:CPNCO-50/20kph/day"
    out = tmp_path / "cpnco.html"
    result = invoke("view", test_id, "--out", out, "--no-open")
    assert result.exit_code == 0, result.output
    scenario = scenario_of(test_id)
    rec = record([scenario])[0]
    page, problems = ready(browser, out)
    t_s = 2.0  # a frame time: no interpolation
    page.evaluate(f"window.vrusimPlayer.players['player'].seek({t_s})")
    seen, shadow = page.evaluate(SECTOR_JS)
    i = rec.nearest_index(t_s)
    trace = rec.trace
    hx, hy = trace["ego_heading_x"][i], trace["ego_heading_y"][i]
    half = scenario.ego.length_m / 2
    apex = np.array([trace["ego_x_m"][i] + hx * half, trace["ego_y_m"][i] + hy * half])
    sensor = scenario.sensor
    expected = visible_sector_xy(apex, math.degrees(math.atan2(hy, hx)), sensor.fov_deg, 20.0, _box_frames(scenario))
    assert np.allclose(seen[0], apex, atol=2e-3)
    assert np.allclose(np.array(seen[1:]), expected[1::2], atol=5e-3)  # the apex, then every other ray
    reach = np.hypot(*(np.array(seen[1:]) - apex).T)
    assert (reach < 19.9).sum() > 10  # the parked cars do cut it
    assert len(shadow) == 2 * (len(seen) - 1)  # the cut points, then the full arc back
    assert np.allclose(np.hypot(*(np.array(shadow[len(seen) - 1 :]) - apex).T), 20.0, atol=5e-3)
    assert problems == []

"""Screenshots of the scene player for the paper's three cases, V2X off and on compared side by side.

Run: python docs/player_screenshots.py   (writes docs/img/player_<case>.png; needs Chromium at /usr/bin/chromium
or $VRUSIM_CHROMIUM and the playwright package, as the browser tests do; nothing is downloaded)

Each page is what `vrusim view paper:<case> --v2x off,on` writes; the picture is taken at the moment the V2X-off
run first perceives the VRU (the V2X-on run has known of it for a while by then).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from vrusim.paper.cases import CASES
from vrusim.report import write_report
from vrusim.report.view import view_report
from vrusim.sources import scenario_of
from vrusim.viz.recording import record

OUT = Path(__file__).parent / "img"
CHROMIUM = Path(os.environ.get("VRUSIM_CHROMIUM", "/usr/bin/chromium"))
WIDTH_PX = 1000
"""Browser viewport width, CSS px (the player is at most 900 px wide)."""


def main() -> None:
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as folder, sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=["--no-sandbox"])
        for case in CASES:
            recordings = record([scenario_of(f"paper:{case.key}", False), scenario_of(f"paper:{case.key}", True)])
            page_file = Path(folder) / f"{case.key}.html"
            write_report(view_report(recordings, note=f"paper:{case.key}"), page_file)
            at_s = recordings[0].events_s.get("first_perception", 0.0)
            page = browser.new_page(viewport={"width": WIDTH_PX, "height": 900})
            page.goto(page_file.resolve().as_uri(), wait_until="load")
            page.wait_for_selector("div.player[data-ready='true']")
            page.evaluate(f"window.vrusimPlayer.players['player'].seek({at_s})")
            target = OUT / f"player_{case.key}.png"
            page.locator("div.player").screenshot(path=str(target))
            page.close()
            print(f"{target} at t = {at_s:.2f} s ({target.stat().st_size / 1024:.0f} KiB)")
        browser.close()


if __name__ == "__main__":
    main()

"""The report page: one HTML document with its style sheet, script, figures and results JSON inline.

A Content-Security-Policy in the page allows only inline styles, inline scripts and `data:` images, so a
browser refuses (and reports) any attempt to load something from elsewhere: the file stays self-contained.
"""

from __future__ import annotations

import platform
import sys
from dataclasses import dataclass
from datetime import UTC, datetime
from functools import cache
from importlib import resources
from typing import Any

from vrusim.report.html import Html, esc, facts, join, script_json, tag
from vrusim.version import __version__, source_digest

CONTENT_SECURITY_POLICY = (
    "default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'; base-uri 'none'; "
    "form-action 'none'"
)
"""Nothing but what is inside the file may load."""
PLAYER_MARK = '<div class="player"'
"""How a section holding a scene player (`report.player`) starts it: the page then inlines player.js and .css."""
RESULTS_ID = "results"
"""id of the `<script type="application/json">` holding the report's results document."""


@dataclass(frozen=True)
class Section:
    """A titled part of the report (`anchor` is its id, linked from the table of contents)."""

    anchor: str
    title: str
    content: Html


@dataclass(frozen=True)
class Report:
    """A report before rendering: kind ("run", "paper", "ncap", "sweep"), title, lead text, sections, results."""

    kind: str
    title: str
    lead: str
    sections: list[Section]
    results: dict[str, Any]
    """The numbers shown, as plain JSON data (embedded as `#results`)."""


@cache
def asset(name: str) -> str:
    """Text of a file in vrusim/report/assets."""
    return (resources.files("vrusim.report") / "assets" / name).read_text(encoding="utf-8")


def code_version() -> dict[str, str]:
    """What produced the report: vrusim version, source digest, Python, platform, time (UTC, ISO 8601)."""
    return {
        "vrusim": __version__,
        "source_digest": source_digest(),
        "python": sys.version.split()[0],
        "platform": platform.platform(terse=True),
        "generated_utc": datetime.now(UTC).replace(microsecond=0).isoformat(),
    }


def _version_section(version: dict[str, str]) -> Section:
    labels = {
        "vrusim": "vrusim version",
        "source_digest": "source digest (SHA-256 of the package's .py files)",
        "python": "Python",
        "platform": "platform",
        "generated_utc": "generated (UTC)",
    }
    items = [(labels[key], tag("span", value, id=f"version-{key.replace('_', '-')}")) for key, value in version.items()]
    return Section("code-version", "Code version", facts(items))


def render(report: Report) -> str:
    """The complete, self-contained HTML document of a report."""
    version = code_version()
    sections = [*report.sections, _version_section(version)]
    toc = tag("nav", *(tag("a", s.title, href=f"#{s.anchor}") for s in sections), class_="toc")
    body = [
        tag("header", tag("h1", report.title), tag("p", report.lead, class_="lead"), toc),
        tag("main", *(tag("section", tag("h2", s.title), s.content, id=s.anchor) for s in sections)),
        tag("footer", tag("p", f"vrusim {version['vrusim']} · {report.kind} report", class_="note")),
        script_json({"kind": report.kind, "code": version, **report.results}, element_id=RESULTS_ID),
        Html(f"<script>{asset('report.js')}</script>"),
    ]
    players = any(PLAYER_MARK in s.content for s in sections)
    if players:
        body.append(Html(f"<script>{asset('player.js')}</script>"))
    head = join(
        [
            Html('<meta charset="utf-8">'),
            Html(f'<meta http-equiv="Content-Security-Policy" content="{esc(CONTENT_SECURITY_POLICY)}">'),
            Html('<meta name="viewport" content="width=device-width, initial-scale=1">'),
            Html(f'<meta name="generator" content="vrusim {esc(version["vrusim"])}">'),
            tag("title", report.title),
            Html(f"<style>{asset('report.css')}</style>"),
            Html(f"<style>{asset('player.css')}</style>") if players else None,
        ]
    )
    opening = f'<!DOCTYPE html>\n<html lang="en" data-kind="{esc(report.kind)}">\n'
    return f"{opening}<head>{head}</head>\n<body>{join(body)}</body>\n</html>\n"

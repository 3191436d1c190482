"""Every relative link of the README and docs/ names a file of the repository and, after a `#`, one of that
page's headings (GitHub's anchors): a renamed heading or module must not leave a dead link behind."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def github_anchor(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """Every heading anchor of a markdown page (a repeated heading gets -1, -2, ... as on GitHub)."""
    seen: dict[str, int] = {}
    found = set()
    for line in _prose_lines(page):
        heading = re.match(r"#{1,6}\s+(.*)", line[1])
        if heading:
            base = github_anchor(heading.group(1))
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
    return found


def _prose_lines(page: Path) -> list[tuple[int, str]]:
    """(line number, text) of the page's lines outside fenced code blocks."""
    lines, fenced = [], False
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced:
            lines.append((number, line))
    return lines


def dead_links(page: Path) -> list[str]:
    """The page's relative links whose file or heading does not exist, as "page:line: target"."""
    dead = []
    for number, line in _prose_lines(page):
        for target in LINK.findall(line):
            if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
                continue
            path, _, fragment = target.partition("#")
            linked = (page.parent / path).resolve() if path else page
            if not linked.exists():
                dead.append(f"{page.name}:{number}: {target} (no such file)")
            elif fragment and linked.suffix == ".md" and fragment not in anchors(linked):
                dead.append(f"{page.name}:{number}: {target} (no such heading)")
    return dead


def test_github_anchor_follows_githubs_rule():
    assert github_anchor("Engine step (`engine/stepper.py`, `engine/simulate.py`)") == (
        "engine-step-enginestepperpy-enginesimulatepy"
    )
    assert github_anchor("Safety: the more critical of time and space") == "safety-the-more-critical-of-time-and-space"
    assert github_anchor("Low-speed reference functions (`acpe`, `reverse_aeb`, `dow`)") == (
        "low-speed-reference-functions-acpe-reverse_aeb-dow"
    )


def test_a_dead_link_is_found(tmp_path):
    (tmp_path / "other.md").write_text("# Title\n\n## A section\n")
    page = tmp_path / "page.md"
    page.write_text(
        "[ok](other.md#a-section) [self](#intro) [web](https://example.org/x#y)\n"
        "```\n[in code](missing.md)\n```\n# Intro\n"
        "[gone](other.md#old-section) [nofile](missing.md)\n"
    )
    assert dead_links(page) == [
        "page.md:6: other.md#old-section (no such heading)",
        "page.md:6: missing.md (no such file)",
    ]


@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_every_relative_link_resolves(page):
    assert dead_links(page) == []

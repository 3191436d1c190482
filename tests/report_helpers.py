"""Shared helpers of the report tests: read the tables, references and results block of a report's HTML."""

from __future__ import annotations

import json
import math
from html.parser import HTMLParser
from typing import Any

Z95 = 1.959963984540054


class _Reader(HTMLParser):
    """Collects table cells (by table id, row key, column key), src/href values, tags and the results block."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tables: dict[str, dict[str, dict[str, Any]]] = {}
        self.references: list[tuple[str, str, str]] = []
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self._table: str | None = None
        self._row: str | None = None
        self._in_results = False
        self.results_text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attributes = dict(attrs)
        self.tags.append((tag, attributes))
        for name in ("src", "href", "action", "poster", "data"):
            if attributes.get(name):
                self.references.append((tag, name, attributes[name] or ""))
        if tag == "table" and attributes.get("class") == "data":
            self._table = attributes["id"]
            self.tables[self._table] = {}
        elif tag == "tr" and self._table is not None and "data-row" in attributes:
            self._row = attributes["data-row"]
            self.tables[self._table][self._row] = {}
        elif tag == "td" and self._row is not None and "data-value" in attributes:
            self.tables[self._table][self._row][attributes["data-col"]] = json.loads(attributes["data-value"])
        elif tag == "script" and attributes.get("id") == "results":
            self._in_results = True

    def handle_endtag(self, tag: str) -> None:
        if tag == "table":
            self._table = self._row = None
        elif tag == "script":
            self._in_results = False

    def handle_data(self, data: str) -> None:
        if self._in_results:
            self.results_text += data


def read_report(text: str) -> _Reader:
    """Parse a report's HTML."""
    reader = _Reader()
    reader.feed(text)
    reader.close()
    return reader


def external_references(text: str) -> list[tuple[str, str, str]]:
    """(tag, attribute, value) of every src/href/... that points outside the file (anything but data: and #)."""
    return [ref for ref in read_report(text).references if not ref[2].startswith(("data:", "#"))]


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of k successes in n trials (the textbook closed form)."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return max(0.0, centre - half), min(1.0, centre + half)


def same(a: Any, b: Any, tolerance: float = 1e-9) -> bool:
    """Equal, numbers within `tolerance` (relative or absolute); None only equals None."""
    if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, int | float) or not isinstance(b, int | float):
        return a == b
    return math.isclose(a, b, rel_tol=tolerance, abs_tol=tolerance)

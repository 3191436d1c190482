"""Shared helpers of the OpenSCENARIO import tests: edit a file in place, and import one that must be refused."""

from __future__ import annotations

from pathlib import Path

from cli_helpers import invoke


def edited(path: Path, old: str, new: str, count: int = 1, last: bool = False) -> Path:
    """`path` with `old` (which must occur) replaced by `new`, `count` times (with `last`: its last occurrence)."""
    text = path.read_text()
    assert old in text, old
    if last:
        head, _, tail = text.rpartition(old)
        path.write_text(head + new + tail)
    else:
        path.write_text(text.replace(old, new, count))
    return path


def refused(path: Path, *words: str) -> str:
    """`vrusim import path`: exit 2, no traceback, every word in the one-line message (returned)."""
    result = invoke("import", str(path), "--out", str(path.with_suffix(".yaml")))
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    message = " ".join(result.output.split())
    for word in words:
        assert word in message, (word, message)
    return message


def refused_at(path: Path, marker: str, *words: str, last: bool = False) -> str:
    """`vrusim import path`: exit 2, no traceback; the one-line message (returned) names the file, the line holding
    `marker` (its first, or with `last` its last occurrence) and every word of `words`."""
    message = refused(path, path.name, *words)
    lines = [n for n, text in enumerate(path.read_text().splitlines(), 1) if marker in text]
    line = lines[-1] if last else lines[0]
    assert f"line {line}:" in message, (line, message)
    return message

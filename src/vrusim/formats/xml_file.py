"""Read a user's XML file safely into a small element tree that keeps each element's line number.

A file is data from anyone: it must be a regular UTF-8 file of at most `input_file_bytes` (checked before
reading, `vrusim.limits`), and any document type declaration (`<!DOCTYPE`) is refused before it is processed,
so there are no entity definitions to expand ("billion laughs") and no external entities or DTDs to fetch.
Text content is dropped (OpenDRIVE and OpenSCENARIO keep their data in attributes). Every failure is a
UserInputError naming the file and line.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from vrusim.errors import UserInputError
from vrusim.limits import check_limit, excess
from vrusim.scenario.yaml_file import read_checked_text

_SHOWN_CHARS = 40
"""A name taken from the file is shown shortened to this many characters."""


@dataclass
class Element:
    """An XML element: tag, attributes, the line it starts on (1-based) and its child elements in order."""

    tag: str
    attrib: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)

    def all(self, tag: str) -> list[Element]:
        """The children named `tag`, in document order."""
        return [child for child in self.children if child.tag == tag]

    def first(self, tag: str) -> Element | None:
        """The first child named `tag`, or None."""
        return next((child for child in self.children if child.tag == tag), None)


def shown(text: str) -> str:
    """A name from a file, quoted and shortened, safe to put in a message."""
    return repr(text if len(text) <= _SHOWN_CHARS else text[:_SHOWN_CHARS] + "...")


class _RefusedError(Exception):
    """A construct the reader refuses (a DTD, an entity): its message says which."""


def parse_xml(text: str, source: str) -> Element:
    """The root element of the XML document `text` (from file `source`, for messages)."""
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        element = Element(tag, attrib, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(_tag: str) -> None:
        stack.pop()

    def refuse(what: str):  # type: ignore[no-untyped-def]
        def handler(*_args: object) -> None:
            raise _RefusedError(what)

        return handler

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = refuse("a document type declaration (<!DOCTYPE>) is not accepted")
    parser.EntityDeclHandler = refuse("an entity declaration is not accepted")
    parser.ExternalEntityRefHandler = refuse("an external entity is not accepted")
    parser.SkippedEntityHandler = refuse("an undefined entity is not accepted")
    try:
        parser.Parse(text, True)
    except _RefusedError as error:
        raise UserInputError(f"{source}: line {parser.CurrentLineNumber}: {error}") from None
    except expat.ExpatError as error:
        raise UserInputError(
            f"{source}: line {error.lineno}: not well-formed XML ({expat.ErrorString(error.code)})"
        ) from None
    if not roots:
        raise UserInputError(f"{source}: no XML element")
    return roots[0]


def read_xml_file(path: Path, kind: str) -> Element:
    """The root element of the XML file `path` (a `kind` file, e.g. "OpenDRIVE"); refused as described above."""
    return parse_xml(read_checked_text(Path(path), kind), str(path))


def attribute_number(
    fail: Callable[[Element, str], UserInputError], source: str, element: Element, name: str, text: str
) -> float:
    """The finite number `text` of attribute `name` of `element` in file `source`, at most `xml_number` in
    magnitude; otherwise `fail(element, reason)` is raised (the text no longer than `number_chars` either)."""
    check_limit("number_chars", len(text), f"{source}: line {element.line}: <{element.tag}> {name}")
    try:
        value = float(text)
    except ValueError:
        raise fail(element, f"attribute {name}: expected a number, got {shown(text)}") from None
    if not math.isfinite(value):
        raise fail(element, f"attribute {name}: expected a finite number, got {shown(text)}")
    reason = excess("xml_number", value)
    if reason is not None:
        raise fail(element, f"attribute {name}: {reason}")
    return value

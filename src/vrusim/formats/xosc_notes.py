"""What an import leaves out: elements that do not change the motion, listed as warnings.

Lights and appearance (`AppearanceAction`, `LightStateAction`) are always accepted and listed. Weather, road
conditions and controller assignments are listed only with `lenient` (`--lenient`); without it they are
refused, like every element that changes the motion (docs/openscenario_import.md, "Actions and conditions").
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vrusim.formats.xml_file import Element
from vrusim.formats.xosc_document import XoscDocument


@dataclass
class ImportNotes:
    """The warnings of one import and whether motion-neutral unsupported elements are tolerated."""

    lenient: bool = False
    warnings: list[str] = field(default_factory=list)

    def ignore(self, element: Element, why: str) -> None:
        """List `element` as ignored (it has no effect on the run)."""
        self.warnings.append(f"line {element.line}: <{element.tag}> ignored: {why}")

    def tolerate(self, doc: XoscDocument, element: Element, why: str) -> None:
        """Ignore `element` with `lenient`, else refuse it."""
        if not self.lenient:
            raise doc.fail(element, f"is not supported ({why}; --lenient ignores it with a warning)")
        self.ignore(element, why)

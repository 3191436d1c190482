"""Matplotlib figures inside the report: PNG bytes as a `data:` URI in an `<img>` with its pixel size."""

from __future__ import annotations

import base64
import io
import struct

from matplotlib.figure import Figure

from vrusim.report.html import Html, tag, void
from vrusim.viz.literal_text import drawing

DEFAULT_DPI = 90.0
"""Resolution of embedded figures, dots per inch (a compromise between sharpness and file size)."""


def png_bytes(fig: Figure, dpi: float = DEFAULT_DPI) -> bytes:
    """The figure as PNG."""
    buffer = io.BytesIO()
    with drawing(fig):
        fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def png_size(data: bytes) -> tuple[int, int]:
    """(width, height) in pixels from a PNG's IHDR chunk."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def png_figure(data: bytes, alt: str, caption: str, element_id: str) -> Html:
    """An inline PNG (`data:` URI) with caption; width and height attributes keep the layout stable."""
    width, height = png_size(data)
    source = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
    image = void("img", src=source, alt=alt, width=width, height=height, loading="eager", decoding="sync")
    return tag("figure", image, tag("figcaption", caption), id=element_id)


def figure(fig: Figure, alt: str, caption: str, element_id: str, dpi: float = DEFAULT_DPI) -> Html:
    """A matplotlib Figure embedded as PNG with caption."""
    return png_figure(png_bytes(fig, dpi), alt, caption, element_id)

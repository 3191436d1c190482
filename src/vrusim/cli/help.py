"""Help screens without the type label (`<bool>`) Typer prints next to every flag, `--help` included."""

from __future__ import annotations

from typing import Any

from typer.core import TyperCommand, TyperGroup


def _hide_flag_types(params: list[Any]) -> None:
    """A flag takes no value, so it shows none: an empty metavar replaces Typer's `<bool>`."""
    for param in params:
        if getattr(param, "is_flag", False) and param.metavar is None:
            param.metavar = ""


class Command(TyperCommand):
    """A `vrusim` command whose help lists flags without a type."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        _hide_flag_types(self.get_params(ctx))
        super().format_help(ctx, formatter)


class Group(TyperGroup):
    """The `vrusim` app, whose help lists flags without a type."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        _hide_flag_types(self.get_params(ctx))
        super().format_help(ctx, formatter)

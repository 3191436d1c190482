"""Read a YAML document from a user's file: safe loading, a repeated key is an error, every failure a UserInputError."""

from __future__ import annotations

from pathlib import Path

import yaml

from vrusim.errors import UserInputError


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, except that a mapping may not name one key twice (PyYAML keeps the last silently)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        seen: set = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # `<<: *anchor` may be overridden by explicit keys
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                repeated = key in seen
            except TypeError:  # an unhashable key: let PyYAML report it
                continue
            if repeated:
                mark = key_node.start_mark
                raise yaml.constructor.ConstructorError(None, None, f"key {key!r} appears twice in one mapping", mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def parse_yaml(text: str) -> object:
    """The document in `text`; raises yaml.YAMLError on bad syntax or a repeated key."""
    return yaml.load(text, Loader=_UniqueKeyLoader)  # a SafeLoader subclass: safe


def read_yaml_file(path: Path, kind: str) -> object:
    """The parsed YAML document in `path`; a missing, unreadable or malformed file is a UserInputError."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserInputError(f"{path}: no such {kind} file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise UserInputError(f"{path}: cannot read {kind} file ({error.__class__.__name__}: {error})") from None
    try:
        return parse_yaml(text)
    except yaml.YAMLError as error:
        raise UserInputError(f"{path}: not valid YAML ({_describe(error)})") from None


def _describe(error: yaml.YAMLError) -> str:
    """`line L, column C: problem` for errors that carry a position (all of PyYAML's parse errors), else the text."""
    mark = getattr(error, "problem_mark", None)
    problem = getattr(error, "problem", None)
    if mark is None or problem is None:
        return str(error)
    context = getattr(error, "context", None)
    return f"line {mark.line + 1}, column {mark.column + 1}: {problem}" + (f" ({context})" if context else "")

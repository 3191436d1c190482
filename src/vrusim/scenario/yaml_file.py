"""Read a YAML document from a user's file: safe loading, a repeated key is an error, every failure a UserInputError.

A file is data from anyone, so reading is bounded before it starts (`vrusim.limits`, docs/limits.md): regular
files only (not a device, FIFO or folder, even behind a symlink), at most `input_file_bytes`, nesting at most
`yaml_depth` levels, at most `yaml_nodes` values counting every use of an alias, numbers of at most
`number_chars` characters and lists of at most `list_items` items.

PyYAML reads YAML 1.1, whose numbers include forms that YAML 1.2 and most people read differently: `010` is
octal (8), `1:30` base 60 (90), `0b11` binary (3). Such a plain scalar is refused with its line and the number
it would have been, so a value never changes silently (`AmbiguousNumberError`); quoted it is text.
"""

from __future__ import annotations

import re
import stat
from pathlib import Path

import yaml

from vrusim.errors import UserInputError
from vrusim.limits import amount, check_limit, limit


class InputLimitError(yaml.YAMLError):
    """A document beyond one of the input limits (its message says which)."""


class AmbiguousNumberError(yaml.MarkedYAMLError):
    """A plain scalar that YAML 1.1 reads as an octal, base-60 or binary number (its message says how to write it)."""


_YAML11_NUMBERS = (
    (re.compile(r"[-+]?0b[0-1_]+"), "binary"),
    (re.compile(r"[-+]?0[0-7_]+"), "octal"),
    (re.compile(r"[-+]?[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?"), "base-60"),
)
"""The number forms of YAML 1.1 that YAML 1.2 reads otherwise (PyYAML's resolver patterns), and their names."""


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, except that a mapping may not name one key twice (PyYAML keeps the last silently),
    with the nesting, list-length and number-length limits checked while composing."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._max_depth = limit("yaml_depth")
        self._max_items = limit("list_items")
        self._max_number = limit("number_chars")

    def compose_node(self, parent, index):  # type: ignore[no-untyped-def]
        self._depth += 1
        try:
            if self._depth > self._max_depth:
                raise InputLimitError(f"nested deeper than the limit of {amount(self._max_depth)} levels")
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        if isinstance(node, yaml.SequenceNode) and len(node.value) > self._max_items:
            raise InputLimitError(
                f"a list of {amount(len(node.value))} items exceeds the limit of {amount(self._max_items)}"
            )
        if isinstance(node, yaml.ScalarNode) and node.tag in _NUMBER_TAGS:
            if len(node.value) > self._max_number:
                raise InputLimitError(
                    f"a number of {amount(len(node.value))} characters exceeds the limit of {amount(self._max_number)}"
                )
            self._check_unambiguous(node)
        return node

    def _check_unambiguous(self, node: yaml.ScalarNode) -> None:
        """Refuse a plain number in one of the YAML 1.1 forms of `_YAML11_NUMBERS`, saying what to write."""
        if node.style is not None:
            return
        for pattern, form in _YAML11_NUMBERS:
            if pattern.fullmatch(node.value):
                value = self.construct_object(node)
                hint = f"write {value} if you mean it"
                decimal = int(node.value.replace("_", "")) if form == "octal" else value
                if decimal != value:
                    hint += f", {decimal} if not (no leading zero)"
                problem = f"{node.value} is the {form} number {value} in YAML 1.1; {hint}, or '{node.value}' for text"
                raise AmbiguousNumberError(None, None, problem, node.start_mark)

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


_NUMBER_TAGS = ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")


def _expanded_size(root: yaml.Node) -> int:
    """Values in the document with every alias expanded (shared nodes counted per use), without expanding it."""
    sizes: dict[int, int] = {}
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, children_done = stack.pop()
        if id(node) in sizes:
            continue
        children = _children(node)
        if children_done or not children:
            sizes[id(node)] = 1 + sum(sizes[id(child)] for child in children)
            continue
        stack.append((node, True))
        stack.extend((child, False) for child in children if id(child) not in sizes)
    return sizes[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def parse_yaml(text: str) -> object:
    """The document in `text`; raises yaml.YAMLError on bad syntax, a repeated key or an input limit."""
    loader = _UniqueKeyLoader(text)
    try:
        root = loader.get_single_node()
        if root is None:
            return None
        size = _expanded_size(root)
        if size > limit("yaml_nodes"):
            raise InputLimitError(
                f"{amount(size)} values (aliases expanded) exceed the limit of {amount(limit('yaml_nodes'))}"
            )
        return loader.construct_document(root)
    finally:
        loader.dispose()


def read_yaml_file(path: Path, kind: str) -> object:
    """The parsed YAML document in `path`; a missing, special, oversized, unreadable or malformed file is a
    UserInputError."""
    text = read_checked_text(path, kind)
    try:
        return parse_yaml(text)
    except InputLimitError as error:
        raise UserInputError(f"{path}: {error} (docs/limits.md)") from None
    except AmbiguousNumberError as error:
        raise UserInputError(f"{path}: {_describe(error)}") from None
    except yaml.YAMLError as error:
        raise UserInputError(f"{path}: not valid YAML ({_describe(error)})") from None


def read_checked_text(path: Path, kind: str) -> str:
    """The text of a regular file of at most `input_file_bytes`, checked before reading it."""
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise UserInputError(f"{path}: not a regular file; a {kind} file must be a plain file")
        check_limit("input_file_bytes", info.st_size, f"{path}")
        with path.open("rb") as stream:
            data = stream.read(int(limit("input_file_bytes")) + 1)
        check_limit("input_file_bytes", len(data), f"{path}")
        return data.decode("utf-8")
    except FileNotFoundError:
        raise UserInputError(f"{path}: no such {kind} file") from None
    except (OSError, ValueError) as error:  # ValueError: a null byte or an undecodable file
        raise UserInputError(f"{path}: cannot read {kind} file ({error.__class__.__name__}: {error})") from None


def _describe(error: yaml.YAMLError) -> str:
    """`line L, column C: problem` for errors that carry a position (all of PyYAML's parse errors), else the text."""
    mark = getattr(error, "problem_mark", None)
    problem = getattr(error, "problem", None)
    if mark is None or problem is None:
        return str(error)
    context = getattr(error, "context", None)
    return f"line {mark.line + 1}, column {mark.column + 1}: {problem}" + (f" ({context})" if context else "")

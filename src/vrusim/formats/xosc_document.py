"""Strict access to an OpenSCENARIO element tree: parameter references resolved, unknown children refused.

Attribute values may be a parameter reference, `$name` or `${name}`, to a `<ParameterDeclaration>` of the file
(declarations may refer to earlier ones), or an expression, `${$a + 1}` (`xosc_expression`). Each declared value
is converted to its `parameterType` (`xosc_parameters`); values given from outside (a parameter distribution)
replace the declared ones. Every failure is a UserInputError naming the file, the line and the element.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import Element, attribute_number, shown
from vrusim.formats.xosc_expression import ExpressionError, Value, evaluate, value_text
from vrusim.formats.xosc_parameters import convert, parameter_type
from vrusim.io.paths import check_name

_REFERENCE = re.compile(r"^\$(?:\{([A-Za-z_][A-Za-z0-9_]*)\}|([A-Za-z_][A-Za-z0-9_]*))$")


class XoscDocument:
    """One `.xosc` file: its name (for messages) and its declared parameters (name -> resolved value text)."""

    def __init__(self, source: str, overrides: dict[str, str] | None = None) -> None:
        self.source = source
        self.parameters: dict[str, str] = {}
        self.values: dict[str, Value | str] = {}
        """Typed values (double or bool; text for string and dateTime) of the parameters, as expressions see them."""
        self.overrides = dict(overrides or {})
        """Parameter values given from outside (name -> text), replacing the declared values."""
        self.variables: dict[str, str] = {}
        """Declared variables (name -> value text, typed like parameters); kept at their declared values."""
        self.catalogs: Any = None
        """The scenario's catalog locations (`xosc_catalogs.Catalogs`; not imported here: it imports this module);
        None: catalog references are refused (`xosc_catalogs.catalog_entry`)."""

    def fail(self, element: Element, message: str) -> UserInputError:
        """A user error at `element`: file, line, element tag, message."""
        return UserInputError(f"{self.source}: line {element.line}: <{element.tag}> {message}")

    def unsupported(self, element: Element, where: str | None = None) -> UserInputError:
        """`element` is outside the subset vrusim imports (docs/openscenario_import.md)."""
        inside = f" inside <{where}>" if where else ""
        return self.fail(
            element, f"is not supported{inside} (vrusim imports the subset in docs/openscenario_import.md)"
        )

    # ------------------------------------------------------------------------------------------- parameters

    def declare(self, declarations: Element | None) -> None:
        """Read `<ParameterDeclarations>`: each value resolved against the parameters declared before it."""
        for element in self.children(declarations or Element("ParameterDeclarations", {}, 0), {"ParameterDeclaration"}):
            self.children(element, set())
            name = self.raw(element, "name")
            kind = parameter_type(self.raw(element, "parameterType", ""))
            if kind is None:
                raise self.fail(
                    element, f"attribute parameterType: {shown(element.attrib['parameterType'])} is unknown"
                )
            given = name in self.overrides
            text = self.overrides.pop(name) if given else self.text(element, "value")
            try:
                self.parameters[name], value = convert(text, kind)
            except ValueError as error:
                origin = "the value given for it" if given else "attribute value"
                raise self.fail(element, f"parameter {shown(name)}: {origin}: {error}") from None
            self.values[name] = value
        if self.overrides:
            names = ", ".join(shown(n) for n in sorted(self.overrides))
            raise UserInputError(f"{self.source}: parameter(s) {names} given a value but not declared in the file")

    def scoped(self, declarations: Element | None) -> XoscDocument:
        """The scope inside an element with its own `<ParameterDeclarations>` (a Story, a Maneuver, a Trajectory,
        a Route): ASAM OpenSCENARIO 1.3 section 9.1 makes a parameter's scope the subtree of the element that
        declares it, so the inner declarations add to the enclosing parameters and hide any of the same name.
        Without declarations (or with none inside), `self`."""
        if declarations is None or not declarations.children:
            return self
        inner = XoscDocument(self.source)
        inner.parameters, inner.values = dict(self.parameters), dict(self.values)
        inner.variables, inner.catalogs = self.variables, self.catalogs
        inner.declare(declarations)
        return inner

    def declare_variables(self, declarations: Element | None) -> None:
        """Read `<VariableDeclarations>` (OpenSCENARIO 1.2): each value typed like a parameter's (its `value` may
        refer to parameters). Variables are not `$name` references; conditions and actions on them are refused."""
        for element in self.children(declarations or Element("VariableDeclarations", {}, 0), {"VariableDeclaration"}):
            self.children(element, set())
            name = self.raw(element, "name")
            kind = parameter_type(self.raw(element, "variableType"))
            if kind is None or kind == "infer":
                raise self.fail(element, f"attribute variableType: {shown(element.attrib['variableType'])} is unknown")
            if name in self.variables:
                raise self.fail(element, f"variable {shown(name)} is declared twice")
            try:
                self.variables[name] = convert(self.text(element, "value"), kind)[0]
            except ValueError as error:
                raise self.fail(element, f"variable {shown(name)}: attribute value: {error}") from None

    def resolve(self, element: Element, name: str, text: str) -> str:
        """The value of an attribute: a parameter reference replaced by the parameter's value."""
        if not text.startswith("$"):
            return text
        match = _REFERENCE.match(text)
        if match is None:
            return self.expression(element, name, text)
        parameter = match.group(1) or match.group(2)
        if parameter not in self.parameters:
            raise self.fail(element, f"attribute {name}: parameter {shown(parameter)} is not declared")
        return self.parameters[parameter]

    def expression(self, element: Element, name: str, text: str) -> str:
        """The value of the expression `${...}` in attribute `name`, as attribute text."""
        if not (text.startswith("${") and text.endswith("}")):
            raise self.fail(element, f"attribute {name}: {shown(text)} is neither $name nor an expression ${{...}}")
        try:
            return value_text(evaluate(text[2:-1], self.values))
        except ExpressionError as error:
            raise self.fail(element, f"attribute {name}: expression {shown(text)}: {error}") from None

    # ------------------------------------------------------------------------------------------- attributes

    def raw(self, element: Element, name: str, default: str | None = None) -> str:
        """An attribute as written (no parameter resolution); missing without default is an error."""
        value = element.attrib.get(name, default)
        if value is None:
            raise self.fail(element, f"has no attribute {name!r}")
        return value

    def text(self, element: Element, name: str, default: str | None = None) -> str:
        """An attribute, its parameter reference resolved."""
        return self.resolve(element, name, self.raw(element, name, default))

    def number(self, element: Element, name: str, default: float | None = None) -> float:
        """A finite number attribute (default when missing and a default is given)."""
        if name not in element.attrib and default is not None:
            return default
        return attribute_number(self.fail, self.source, element, name, self.text(element, name))

    def choice(self, element: Element, name: str, options: tuple[str, ...], default: str | None = None) -> str:
        """An attribute that must be one of `options`."""
        value = self.text(element, name, default)
        if value not in options:
            raise self.fail(element, f"attribute {name}: expected one of {', '.join(options)}, got {shown(value)}")
        return value

    # ------------------------------------------------------------------------------------------- children

    def children(self, element: Element, allowed: set[str]) -> list[Element]:
        """The children of `element`; any child not in `allowed` is refused."""
        for child in element.children:
            if child.tag not in allowed:
                raise self.unsupported(child, element.tag)
        return element.children

    def child(self, parent: Element, tag: str) -> Element:
        """The one child named `tag` (none or several is an error)."""
        found = parent.all(tag)
        if len(found) != 1:
            raise self.fail(parent, f"needs exactly one <{tag}>, has {len(found)}")
        return found[0]

    def optional(self, parent: Element, tag: str) -> Element | None:
        """The child named `tag`, or None; several is an error."""
        found = parent.all(tag)
        if len(found) > 1:
            raise self.fail(found[1], f"may appear once inside <{parent.tag}>")
        return found[0] if found else None

    def single(self, parent: Element, allowed: set[str]) -> Element:
        """The only child of `parent`, which must be one of `allowed`."""
        self.children(parent, allowed)
        if len(parent.children) != 1:
            raise self.fail(parent, f"needs exactly one of <{'>, <'.join(sorted(allowed))}>")
        return parent.children[0]

    def named_path(self, element: Element, attribute: str, base: Path, name: str) -> Path:
        """`base / name`, a file name read from `attribute` of `element`; a user error at the element when the OS
        cannot use it as a name (too long, a null byte), rather than an OSError when it is looked up."""
        return check_name(base / name, f"{self.source}: line {element.line}: <{element.tag}> {attribute}")

    def confined_path(self, element: Element, attribute: str, folder: Path, name: str, owner: str = ".xosc") -> Path:
        """`folder / name` resolved (symlinks followed), a file name read from `attribute` of `element`: it must lie
        inside `folder`, the folder of the `owner` file. An absolute name, or one that leads out of the folder (`..`,
        a symlink), is a user error at the element before anything is looked up or read there."""
        inside = folder.resolve()
        try:
            path = self.named_path(element, attribute, inside, name).resolve()
        except (OSError, RuntimeError) as error:  # a symlink loop
            raise self.fail(element, f"{attribute} {shown(name)} cannot be resolved ({error})") from None
        if Path(name).is_absolute() or not path.is_relative_to(inside):
            raise self.fail(element, f"{attribute} {shown(name)} leads outside the folder of the {owner}; refused")
        return path

    def properties(self, parent: Element) -> dict[str, str]:
        """The `<Properties>` of `parent` (name -> value); `<File>` entries are refused."""
        element = self.optional(parent, "Properties")
        if element is None:
            return {}
        return {self.raw(p, "name"): self.text(p, "value") for p in self.children(element, {"Property"})}

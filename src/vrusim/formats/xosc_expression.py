"""OpenSCENARIO expressions, `${...}` (ASAM OpenSCENARIO XML 1.2/1.3, section "Expressions"), evaluated safely.

A small tokenizer and a recursive-descent parser that evaluates as it parses: nothing is ever handed to `eval`,
and nesting is bounded (`MAX_DEPTH`) so a hostile file gets an `ExpressionError`, never a RecursionError.

Grammar, lowest precedence first (comparisons do not chain):

    or      := and ("or" and)*
    and     := not ("and" not)*
    not     := "not" not | compare
    compare := sum [("==" | "!=" | "<" | "<=" | ">" | ">=") sum]
    sum     := product (("+" | "-") product)*
    product := unary (("*" | "/" | "%") unary)*
    unary   := "-" unary | atom
    atom    := number | "true" | "false" | "$"name | function "(" or ("," or)* ")" | "(" or ")"

Functions: round, floor, ceil (to whole numbers; round halves away from zero), sqrt, sin, cos, tan, asin, acos,
atan (radians), sign, abs, pow (2 arguments), min, max (2 arguments). Numbers are doubles (int parameters
included); `%` is the C remainder (fmod, the dividend's sign). Operators take numbers, except `not`, `and`,
`or` (booleans) and `==`/`!=` (two numbers or two booleans). A non-finite result anywhere is an error.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping

Value = float | bool
"""What an expression evaluates to: a double or a boolean."""

MAX_DEPTH = 64
"""Most nested brackets, unary operators and function calls in one expression."""

_TOKEN = re.compile(
    r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|\$(?P<param>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<word>[A-Za-z_][A-Za-z0-9_]*)|(?P<op>==|!=|<=|>=|[-+*/%<>(),]))"
)


def _round_half_away(x: float) -> float:
    return float(math.floor(abs(x) + 0.5)) * (1.0 if x >= 0 else -1.0)


FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
    "round": (1, _round_half_away),
    "floor": (1, lambda x: float(math.floor(x))),
    "ceil": (1, lambda x: float(math.ceil(x))),
    "sqrt": (1, math.sqrt),
    "sin": (1, math.sin),
    "cos": (1, math.cos),
    "tan": (1, math.tan),
    "asin": (1, math.asin),
    "acos": (1, math.acos),
    "atan": (1, math.atan),
    "sign": (1, lambda x: float((x > 0) - (x < 0))),
    "abs": (1, abs),
    "pow": (2, math.pow),
    "min": (2, min),
    "max": (2, max),
}
"""Each function's argument count and implementation (doubles in, a double out)."""


class ExpressionError(ValueError):
    """An expression that cannot be evaluated: its message says why (the caller adds file, line, text)."""


def _tokens(text: str) -> list[tuple[str, str]]:
    """(kind, text) pairs; kind is number, param, word or op; an ("end", "") pair closes the list."""
    out: list[tuple[str, str]] = []
    position, length = 0, len(text.rstrip())  # trailing blanks end the text: no copy of the rest per token
    while position < length:
        match = _TOKEN.match(text, position)
        if match is None:
            shown = text[position : position + 10].strip()
            raise ExpressionError(f"unexpected {shown!r} at character {position + 1}")
        kind = match.lastgroup
        assert kind is not None
        out.append((kind, match.group(kind)))
        position = match.end()
    out.append(("end", ""))
    return out


def _number(value: Value, what: str) -> float:
    if isinstance(value, bool):
        raise ExpressionError(f"{what} needs numbers, got a boolean")
    return value


def _boolean(value: Value, what: str) -> bool:
    if not isinstance(value, bool):
        raise ExpressionError(f"{what} needs booleans, got a number")
    return value


def _finite(value: float, what: str) -> float:
    if not math.isfinite(value):
        raise ExpressionError(f"{what} gives a non-finite result")
    return value


class _Parser:
    """Evaluates while parsing; `depth` counts the nesting in progress."""

    def __init__(self, text: str, parameters: Mapping[str, Value | str]) -> None:
        self.tokens = _tokens(text)
        self.position = 0
        self.depth = 0
        self.parameters = parameters

    def peek(self) -> tuple[str, str]:
        return self.tokens[self.position]

    def take(self) -> tuple[str, str]:
        token = self.tokens[self.position]
        self.position += 1
        return token

    def accept(self, *ops: str) -> str | None:
        kind, text = self.peek()
        if kind in ("op", "word") and text in ops:
            self.position += 1
            return text
        return None

    def expect(self, op: str) -> None:
        if self.accept(op) is None:
            raise ExpressionError(f"expected {op!r}, got {self.shown()}")

    def shown(self) -> str:
        kind, text = self.peek()
        return "the end" if kind == "end" else repr(text)

    def nest(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(f"nested more than {MAX_DEPTH} levels deep")

    # ------------------------------------------------------------------------------------------- grammar

    def whole(self) -> Value:
        value = self.or_()
        if self.peek()[0] != "end":
            raise ExpressionError(f"unexpected {self.shown()} after a complete expression")
        return value

    def or_(self) -> Value:
        value = self.and_()
        while self.accept("or"):
            right = self.and_()
            value = _boolean(value, "or") | _boolean(right, "or")
        return value

    def and_(self) -> Value:
        value = self.not_()
        while self.accept("and"):
            right = self.not_()
            value = _boolean(value, "and") & _boolean(right, "and")
        return value

    def not_(self) -> Value:
        if self.accept("not"):
            self.nest()
            value = not _boolean(self.not_(), "not")
            self.depth -= 1
            return value
        return self.compare()

    def compare(self) -> Value:
        left = self.sum()
        op = self.accept("==", "!=", "<", "<=", ">", ">=")
        if op is None:
            return left
        right = self.sum()
        if op in ("==", "!="):
            if isinstance(left, bool) != isinstance(right, bool):
                raise ExpressionError(f"{op} compares a boolean with a number")
            return (left == right) == (op == "==")
        a, b = _number(left, op), _number(right, op)
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b}[op]

    def sum(self) -> Value:
        value = self.product()
        while op := self.accept("+", "-"):
            right = _number(self.product(), op)
            left = _number(value, op)
            value = _finite(left + right if op == "+" else left - right, op)
        return value

    def product(self) -> Value:
        value = self.unary()
        while op := self.accept("*", "/", "%"):
            right = _number(self.unary(), op)
            left = _number(value, op)
            if op != "*" and right == 0:
                raise ExpressionError("division by zero" if op == "/" else "remainder (%) by zero")
            value = _finite(left * right if op == "*" else left / right if op == "/" else math.fmod(left, right), op)
        return value

    def unary(self) -> Value:
        if self.accept("-"):
            self.nest()
            value = -_number(self.unary(), "unary -")
            self.depth -= 1
            return value
        return self.atom()

    def atom(self) -> Value:
        kind, text = self.take()
        if kind == "number":
            return _finite(float(text), "the number " + text[:20])
        if kind == "param":
            if text not in self.parameters:
                raise ExpressionError(f"parameter {text!r} is not declared")
            value = self.parameters[text]
            if isinstance(value, str):
                raise ExpressionError(f"parameter {text!r} is a string or dateTime: operators take numbers or booleans")
            return value
        if kind == "word" and text in ("true", "false"):
            return text == "true"
        if kind == "word" and text in FUNCTIONS:
            return self.call(text)
        if kind == "op" and text == "(":
            self.nest()
            value = self.or_()
            self.expect(")")
            self.depth -= 1
            return value
        self.position -= 1
        if kind == "word":
            raise ExpressionError(f"unknown function or word {text!r}")
        raise ExpressionError(f"expected a number, a $parameter, a function or '(', got {self.shown()}")

    def call(self, name: str) -> float:
        count, function = FUNCTIONS[name]
        self.expect("(")
        self.nest()
        arguments = [_number(self.or_(), name)]
        while self.accept(","):
            arguments.append(_number(self.or_(), name))
        self.expect(")")
        self.depth -= 1
        if len(arguments) != count:
            raise ExpressionError(f"{name} takes {count} argument{'s' if count > 1 else ''}, got {len(arguments)}")
        try:
            result = float(function(*arguments))
        except (ValueError, OverflowError):
            result = math.nan
        return _finite(result, f"{name}({', '.join(f'{a:g}' for a in arguments)})")


def evaluate(text: str, parameters: Mapping[str, Value | str]) -> Value:
    """The value of expression `text` (the part inside `${...}`); `parameters` by name (a str value: a string or
    dateTime parameter, refused by every operator)."""
    return _Parser(text, parameters).whole()


def value_text(value: Value) -> str:
    """An expression's value as attribute text: true/false, a whole number without ".0", else repr."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value.is_integer() and abs(value) < 2**53:
        return str(int(value))
    return repr(value)

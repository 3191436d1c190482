"""The package's shape: imports run one way (the layers contract in pyproject.toml) and no modules form a cycle."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parent.parent


def import_cycles(graph: grimp.ImportGraph) -> list[list[str]]:
    """The strongly connected groups of two or more modules (Tarjan's algorithm), each sorted, largest first.

    Imports of a package by its own submodules' `__init__` chain are real imports too, so they count.
    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []

    def visit(start: str) -> None:
        work = [(start, iter(sorted(graph.find_modules_directly_imported_by(start))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            module, targets = work[-1]
            advanced = False
            for target in targets:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append((target, iter(sorted(graph.find_modules_directly_imported_by(target)))))
                    advanced = True
                    break
                if target in on_stack:
                    low[module] = min(low[module], index[target])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[module])
            if low[module] == index[module]:
                group = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.append(member)
                    if member == module:
                        break
                if len(group) > 1:
                    groups.append(sorted(group))

    for module in sorted(graph.modules):
        if module not in index:
            visit(module)
    return sorted(groups, key=len, reverse=True)


def test_no_module_imports_another_that_imports_it_back():
    assert import_cycles(grimp.build_graph("vrusim")) == []


def test_the_cycle_finder_finds_a_planted_cycle():
    graph = grimp.ImportGraph()
    for name in ("p", "p.a", "p.b", "p.c", "p.d"):
        graph.add_module(name)
    graph.add_import(importer="p.a", imported="p.b")
    graph.add_import(importer="p.b", imported="p.c")
    graph.add_import(importer="p.c", imported="p.a")
    graph.add_import(importer="p.c", imported="p.d")
    assert import_cycles(graph) == [["p.a", "p.b", "p.c"]]


def test_the_layers_contract_holds():
    """`lint-imports` (import-linter) checks the contract in pyproject.toml: no module imports upward."""
    done = subprocess.run(
        [sys.executable, "-c", "from importlinter.cli import lint_imports_command; lint_imports_command()"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 broken" in done.stdout


def contract_layers() -> list[grimp.Layer]:
    """The layers of pyproject.toml's contract as grimp layers (optional ones in parentheses included)."""
    contract = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]
    return [
        grimp.Layer(*(name.strip().strip("()") for name in layer.split("|")), independent=True)
        for layer in contract["layers"]
    ]


def test_the_contract_layers_have_no_illegal_dependency():
    assert grimp.build_graph("vrusim").find_illegal_dependencies_for_layers(contract_layers()) == set()


@pytest.mark.parametrize(
    ("lower", "upper"),
    [
        ("vrusim.sim.params", "vrusim.engine.simulate"),
        ("vrusim.scenario.schema", "vrusim.metrics.scores"),
        ("vrusim.ncap.grid", "vrusim.paper.cases"),  # independent siblings
    ],
)
def test_the_layers_refuse_a_planted_upward_import(lower, upper):
    """The same layers, given a graph with one planted import that breaks them, report it: the check can fail."""
    graph = grimp.build_graph("vrusim")
    graph.add_import(importer=lower, imported=upper)
    illegal = graph.find_illegal_dependencies_for_layers(contract_layers())
    assert {(d.importer, d.imported) for d in illegal} == {(lower.rsplit(".", 1)[0], upper.rsplit(".", 1)[0])}

"""OpenSCENARIO 1.2 variables (`XoscDocument.declare_variables`): declarations are read and typed like parameters;
conditions and actions on variables are refused, naming the element and its line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from vrusim.errors import UserInputError
from vrusim.formats.xml_file import parse_xml
from vrusim.formats.xosc_document import XoscDocument
from vrusim.formats.xosc_import import read_xosc
from xosc_helpers import refused

DATA = Path(__file__).parent / "data" / "xosc" / "catalogs"
DECLARATIONS = """<VariableDeclarations>
        <VariableDeclaration name="Count" variableType="int" value="3.0"/>
        <VariableDeclaration name="Armed" variableType="boolean" value="false"/>
        <VariableDeclaration name="Gap" variableType="double" value="$EgoInitialSpeed_mps"/>
    </VariableDeclarations>
    <CatalogLocations/>"""


@pytest.fixture
def inline(tmp_path: Path) -> Path:
    """A copy of the inline export (CPNA-25/20kph/day) with three variables declared."""
    shutil.copy(DATA / "road.xodr", tmp_path / "road.xodr")
    path = tmp_path / "inline.xosc"
    path.write_text((DATA / "inline.xosc").read_text().replace("<CatalogLocations/>", DECLARATIONS, 1))
    return path


def _declared(text: str) -> XoscDocument:
    doc = XoscDocument("v.xosc")
    doc.declare(parse_xml('<P><ParameterDeclaration name="A" parameterType="double" value="2.5"/></P>', "v.xosc"))
    doc.declare_variables(parse_xml(f"<VariableDeclarations>{text}</VariableDeclarations>", "v.xosc"))
    return doc


def test_variables_are_typed_and_do_not_change_the_scenario(inline):
    assert read_xosc(inline) == read_xosc(DATA / "inline.xosc")
    doc = _declared(
        '<VariableDeclaration name="N" variableType="int" value="3.0"/>'
        '<VariableDeclaration name="G" variableType="double" value="$A"/>'
    )
    assert doc.variables == {"N": "3", "G": "2.5"}


@pytest.mark.parametrize(
    ("declaration", "words"),
    [
        ('<VariableDeclaration name="N" variableType="int" value="1.5"/>', ("'N'", "whole number")),
        ('<VariableDeclaration name="N" variableType="float" value="1"/>', ("variableType", "'float'", "unknown")),
        ('<VariableDeclaration name="N" value="1"/>', ("variableType",)),
        ('<VariableDeclaration name="N" variableType="int" value="$B"/>', ("'B'", "not declared")),
    ],
)
def test_a_bad_variable_declaration_isrefused(declaration, words):
    with pytest.raises(UserInputError) as error:
        _declared(declaration)
    for word in ("v.xosc", "line 1", "<VariableDeclaration>", *words):
        assert word in str(error.value)


def test_a_variable_declared_twice_isrefused():
    with pytest.raises(UserInputError, match="declared twice"):
        _declared('<VariableDeclaration name="N" variableType="int" value="1"/>' * 2)


def test_a_variable_condition_that_never_holds_isrefused(inline):
    text = inline.read_text()
    old = '<SimulationTimeCondition value="0.0" rule="greaterOrEqual"/>'
    inline.write_text(text.replace(old, '<VariableCondition variableRef="Count" value="4" rule="equalTo"/>', 1))
    line = next(n for n, row in enumerate(inline.read_text().splitlines(), 1) if "<VariableCondition" in row)
    refused(inline, "<VariableCondition>", f"line {line}", "never holds")


def test_a_variable_action_isrefused(inline):
    text = inline.read_text()
    action = '<GlobalAction><VariableAction variableRef="Count"><SetAction value="4"/></VariableAction></GlobalAction>'
    inline.write_text(text.replace("<Actions>", "<Actions>\n" + action, 1))
    line = next(n for n, row in enumerate(inline.read_text().splitlines(), 1) if "<VariableAction" in row)
    refused(inline, "<VariableAction>", f"line {line}", "variable")

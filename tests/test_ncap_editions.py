"""Euro NCAP editions as data: the registry, selecting by edition, and catalogue names across editions."""

from __future__ import annotations

import pytest

from cli_helpers import assert_user_error, invoke
from vrusim.errors import UserInputError
from vrusim.ncap.editions import DEFAULT_EDITION, EDITION_NAMES, edition
from vrusim.ncap.grid import select
from vrusim.sources import catalogue_tests


def test_every_edition_has_unique_codes_and_test_ids():
    for name in EDITION_NAMES:
        book = edition(name)
        assert book.name == name
        assert len(set(book.codes)) == len(book.codes), name
        ids = [test.test_id for test in select(night=True, protocol=name)]
        assert len(set(ids)) == len(ids), name
        assert {test.protocol for test in select(night=True, protocol=name)} == {name}


def test_default_edition_is_used_when_none_is_named():
    assert edition().name == DEFAULT_EDITION
    assert [t.test_id for t in select()] == [t.test_id for t in select(protocol=DEFAULT_EDITION)]


def test_2023_table_is_the_v451_catalogue():
    book = edition("2023")
    assert "v4.5.1" in book.title
    assert book.scenario("CPNA-25").target_speed_kph == 5.0
    assert all(cell.range == "standard" for spec in book.scenarios for cell in spec.cells)
    with pytest.raises(KeyError):
        book.scenario("CPNA")


@pytest.mark.parametrize("name", ["1999", "", "latest"])
def test_unknown_edition_is_a_user_error_naming_protocol(name):
    with pytest.raises(UserInputError, match="--protocol: unknown edition"):
        edition(name)


@pytest.mark.parametrize("command", ["ncap", "list"])
def test_cli_refuses_an_unknown_protocol_before_running(command):
    assert_user_error(invoke(command, "--protocol", "2019"), "--protocol", "2019", "2023")


def test_edition_prefix_names_a_catalogue_test():
    (test,) = catalogue_tests("2023:CPNA-25/20kph/day", night=False)
    assert (test.protocol, test.test_id) == ("2023", "CPNA-25/20kph/day")
    assert catalogue_tests("2023:NOPE", night=False) == []


def test_unprefixed_names_fall_back_to_the_edition_that_has_them():
    (test,) = catalogue_tests("CPRA-Cm/4kph/adult/day", night=False)
    assert test.protocol == "2023"


def test_list_json_names_the_edition_rows():
    result = invoke("list", "--protocol", "2023", "--json")
    assert result.exit_code == 0
    assert "CPRA-Cs" in result.stdout


def test_the_whole_2026_edition_is_selected_and_a_code_prefix_selects_its_rows():
    assert {t.spec.code for t in select(protocol="2026", night=True)} == set(edition("2026").codes)
    assert {t.spec.code for t in select(["CMFtap"], protocol="2026")} == {"CMFtap", "CMFtap-SfS"}
    assert {t.spec.code for t in select(["CMFtap-S"], protocol="2026")} == {"CMFtap-SfS"}

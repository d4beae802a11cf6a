"""Names that become file names: one rule, and what it accepts."""

from __future__ import annotations

import pytest

from arena.core.errors import ConfigError
from arena.core.names import MAX_NAME_LENGTH, check_label, check_name


@pytest.mark.parametrize("name", ["a", "A-1_b.c", "x" * MAX_NAME_LENGTH, "0", "run.v2", "-x"])
def test_legal_names(name):
    assert check_name(name, "stage name") == name


@pytest.mark.parametrize(
    ("name", "problem"),
    [
        ("", "is empty"),
        (".", "cannot be a file name"),
        ("..", "cannot be a file name"),
        (".hidden", "cannot be a file name"),
        ("a/b", "cannot be a file name"),
        ("a\\b", "cannot be a file name"),
        ("a b", "cannot be a file name"),
        ("é", "cannot be a file name"),
        ("a\0b", "cannot be a file name"),
        ("x" * (MAX_NAME_LENGTH + 1), "longer than 100 characters"),
        (None, "expected a string, got NoneType"),
        (3, "expected a string, got int"),
    ],
)
def test_illegal_names_name_file_and_key(name, problem):
    with pytest.raises(ConfigError) as err:
        check_name(name, "contestant name", source="c.yaml", path="contestants[2].name")
    text = str(err.value)
    assert text.startswith("c.yaml: contestants[2].name: contestant name ")
    assert problem in text
    assert len(text) < 250  # a 300-character name is shortened in the message


def test_labels_are_names_separated_by_slashes():
    assert check_label("default/stage_1", "name") == "default/stage_1"
    for bad in ("a//b", "/a", "a/", "a/../b", "../x"):
        with pytest.raises(ConfigError, match="part"):
            check_label(bad, "name")

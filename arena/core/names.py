"""Names that become file or folder names: one check for all of them.

Experiment names, suite stages, contestants, worlds and every name read back from a run folder
end up as path components (``runs/<name>_<time>``, ``episodes/<contestant>/<stage>/``). A name
with ``/``, ``..`` or a leading dot would write outside its folder or hide a file, and a very
long one fails deep inside the file system; the web app takes such names from users. So every
one goes through :func:`check_name`: 1 to :data:`MAX_NAME_LENGTH` characters out of
``A-Z a-z 0-9 . _ -``, not starting with a dot (which also rules out ``.`` and ``..``).
"""

from __future__ import annotations

import re
from typing import Annotated, Any

from pydantic import AfterValidator

from arena.core.errors import ConfigError, shorten

MAX_NAME_LENGTH = 100
"""Longest name accepted (file systems allow 255 bytes; a name gets prefixes and suffixes)."""

_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*")

RULE = f"1 to {MAX_NAME_LENGTH} of A-Z a-z 0-9 . _ -, not starting with a dot"
"""The rule, as error messages and schema descriptions state it."""


def _shown(value: object) -> str:
    return shorten(repr(value), 60)


def name_problem(value: object) -> str | None:
    """Why ``value`` cannot be a file name (``None`` if it can)."""
    if not isinstance(value, str):
        return f"expected a string, got {type(value).__name__}"
    if not value:
        return "is empty"
    if len(value) > MAX_NAME_LENGTH:
        return f"is longer than {MAX_NAME_LENGTH} characters"
    if not _NAME.fullmatch(value):
        return "cannot be a file name"
    return None


def check_name(
    value: Any, what: str, *, source: str | None = None, path: str | None = None
) -> str:
    """Return ``value`` if it is a safe file name, else raise a one-line error.

    Args:
        value: the name.
        what: what it names, for the message (``"contestant name"``).
        source: the file (or option) it came from.
        path: the key path inside that file (``contestants[2].name``).

    Raises:
        ConfigError: ``<source>: <path>: <what> '<value>' <problem> (use <rule>)``.
    """
    problem = name_problem(value)
    if problem is not None:
        raise ConfigError(f"{what} {_shown(value)} {problem} (use {RULE})".lstrip(),
                          source=source, path=path)
    return str(value)


def check_label(
    value: Any, what: str, *, source: str | None = None, path: str | None = None
) -> str:
    """Like :func:`check_name` for ``/``-separated names (a sub-folder: ``suite/stage``)."""
    if not isinstance(value, str) or "/" not in value:
        return check_name(value, what, source=source, path=path)
    for part in value.split("/"):
        if name_problem(part) is not None:
            raise ConfigError(
                f"{what} {_shown(value)}: part {_shown(part)} {name_problem(part)} "
                f"(use names of {RULE}, separated by '/')".lstrip(),
                source=source, path=path,
            )
    return value


def _validated(check: Any, what: str) -> Any:
    def validate(value: str) -> str:
        try:
            return str(check(value, what))
        except ConfigError as e:  # pydantic wants a ValueError; its location names the key
            raise ValueError(e.message) from None

    return AfterValidator(validate)


SafeName = Annotated[str, _validated(check_name, "")]
"""A pydantic field type for a name that becomes a file name (see :func:`check_name`)."""

SafeLabel = Annotated[str, _validated(check_label, "")]
"""A pydantic field type for ``/``-separated names (see :func:`check_label`)."""

__all__ = [
    "MAX_NAME_LENGTH",
    "RULE",
    "SafeLabel",
    "SafeName",
    "check_label",
    "check_name",
    "name_problem",
]

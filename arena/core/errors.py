"""Typed errors for the whole package.

Every error a user can cause derives from :class:`ArenaError`; the CLI prints those as one line
(no traceback). Errors about input name the file, the key path and what was expected.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any


class ArenaError(Exception):
    """Base class of every error Arena raises on purpose."""


class ConfigError(ArenaError):
    """Invalid configuration or input data.

    Args:
        message: what is wrong and what was expected.
        source: the file the value came from (or ``None`` for values built in code).
        path: the dotted key path inside that file, e.g. ``navigation.local_planner.lookahead``.
    """

    def __init__(self, message: str, *, source: str | None = None, path: str | None = None) -> None:
        self.message = message
        self.source = source
        self.path = path
        super().__init__(self._format())

    def _format(self) -> str:
        where = []
        if self.source:
            where.append(str(self.source))
        if self.path:
            where.append(self.path)
        prefix = ": ".join(where)
        return f"{prefix}: {self.message}" if prefix else self.message

    def located(self, *, source: str | None = None, prefix: str | None = None) -> ConfigError:
        """Return a copy with a file and/or a key-path prefix filled in (outermost wins)."""
        path = self.path
        if prefix:
            path = f"{prefix}.{path}" if path else prefix
        return type(self)(self.message, source=self.source or source, path=path)


class UnknownNameError(ConfigError, KeyError):
    """A name (plugin, robot, world ...) that is not registered."""

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return self._format()


class MapError(ArenaError):
    """A map file or map operation is invalid."""


class PlanningError(ArenaError):
    """Base class of typed planner failures."""


class StartOccupied(PlanningError):
    """The start pose lies in an occupied (or inflated) cell."""


class GoalOccupied(PlanningError):
    """The goal pose lies in an occupied (or inflated) cell."""


class NoPathFound(PlanningError):
    """Start and goal are not connected through free space."""


class SamplingError(ArenaError):
    """A position sampler could not satisfy its constraints."""


class SimulationError(ArenaError):
    """The simulator was used wrongly (e.g. step before reset, wrong command shape)."""


def shorten(text: str, limit: int = 80) -> str:
    """``text`` cut to about ``limit`` characters (a 300-character value stays readable)."""
    return text if len(text) <= limit else f"{text[: limit - 20]}... ({len(text)} characters)"


def format_loc(loc: Iterable[Any]) -> str:
    """Turn a pydantic error location tuple into a dotted path: ``('a', 0, 'b')`` → ``a[0].b``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def from_validation_error(
    err: Any, *, source: str | None = None, prefix: str | None = None
) -> ConfigError:
    """Convert a :class:`pydantic.ValidationError` into one readable :class:`ConfigError`.

    Only the first problem becomes the message's head; the others are appended, so the user sees
    every misspelt key at once while the line still starts with the file and key path.
    """
    errors: Sequence[dict[str, Any]] = err.errors(include_url=False)
    msgs: list[tuple[str, str]] = []
    for e in errors:
        loc = format_loc(e["loc"])
        if e["type"] == "extra_forbidden":
            text = "unknown key (not a field of this block; check the spelling)"
        elif e["type"] == "missing":
            text = "required key is missing"
        elif e["type"] == "value_error" and "error" in e.get("ctx", {}):
            text = str(e["ctx"]["error"])  # our own validators' messages say what they got
        else:
            text = f"{e['msg']} (got {shorten(repr(e.get('input')))})"
        msgs.append((loc, text))

    def full(loc: str) -> str:
        return ".".join(p for p in (prefix, loc) if p)

    head_loc, head_text = msgs[0] if msgs else ("", str(err))
    extra = "".join(f"; {full(loc)}: {text}" for loc, text in msgs[1:])
    return ConfigError(head_text + extra, source=source, path=full(head_loc) or None)

"""Task data files shipped in ``arena/tasks/data/``: curricula, benchmark suites and contests.

A file is named either by a packaged name (``"default"`` → ``data/curricula/default.yaml``) or
by a path. :func:`read_yaml_any` reads any YAML document (curricula are lists) and reports
malformed YAML with the file, line and column; :func:`read_arena_yaml` also reads the ROS 2
port's parameter-file form of the same files.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any, Literal

from arena.core import files
from arena.core.errors import ConfigError

DATA_DIR = Path(__file__).resolve().parent / "data"
"""Folder of the packaged task data files."""

Kind = Literal["curricula", "suites", "contests"]


def packaged(kind: Kind) -> list[str]:
    """Names of the packaged files of one kind (without ``.yaml``)."""
    folder = DATA_DIR / kind
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def find_data_file(kind: Kind, name_or_path: str | Path) -> Path:
    """The file a packaged name or a path names.

    Raises:
        ConfigError: neither an existing file nor a packaged name (with a close match).
    """
    p = Path(name_or_path).expanduser()
    if p.is_file():
        return p
    text = str(name_or_path)
    stem = text[:-5] if text.endswith(".yaml") else text
    candidate = DATA_DIR / kind / f"{stem}.yaml"
    if "/" not in stem and candidate.is_file():
        return candidate
    known = packaged(kind)
    close = difflib.get_close_matches(stem, known, n=1, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ConfigError(
        f"no {kind[:-1] if kind != 'curricula' else 'curriculum'} {text!r}: not a file and not "
        f"a packaged name; {hint}packaged: {', '.join(known) or '(none)'}"
    )


def read_yaml_any(path: str | Path) -> Any:
    """Parse a YAML file of any shape; malformed YAML names the file, line and column."""
    return files.read_yaml(path)


ROS2_PARAMS = "ros__parameters"
"""The key of a ROS 2 parameter file's per-node block."""


def read_arena_yaml(path: str | Path) -> Any:
    """:func:`read_yaml_any` of an Arena task file, unwrapped from a ROS 2 parameter file.

    Arena's ROS 2 port (its ``ros2``/``humble`` branches) stores the same suites, contests,
    benchmark configs and curricula as ROS 2 parameter files: the document sits under
    ``/**: ros__parameters:`` (or ``<node>: ros__parameters:``). A mapping whose only key
    holds only ``ros__parameters`` is read as that block; any other document is returned as is.
    """
    data = read_yaml_any(path)
    if isinstance(data, dict) and len(data) == 1:
        (inner,) = data.values()
        if isinstance(inner, dict) and set(inner) == {ROS2_PARAMS}:
            return inner[ROS2_PARAMS]
    return data

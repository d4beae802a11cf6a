"""The world a suite stage's ``map`` string names: Arena's world names and the worlds folder.

Arena's suites name worlds by folder name (``map: arena_hospital_small``): the folders of
``arena-simulation-setup/worlds``, a repository apart from the suites. A *worlds folder* says
where those are: ``arena bench SUITE --worlds DIR``, else ``suite.worlds`` of a benchmark
``config.yaml``, else the suite file's own ``worlds:`` key (our additions; paths relative to
their file). A world name (no ``/``; checked as a file name, :func:`~arena.core.names.check_name`)
is looked up, first match wins:

1. ``<worlds folder>/<name>/`` (``map/map.yaml`` or ``map.yaml``);
2. next to the suite: ``<suite dir>/<name>``, ``<suite dir>/worlds/<name>``,
   ``<suite dir>/../worlds/<name>``;
3. a folder ``<name>`` in the working directory, then the packaged world ``<name>``.

The worlds folder wins because it is the one place the user named for this run: a world there
that shares its name with a packaged look-alike is the map the suite's authors meant. A ``map``
with ``/`` is a world folder path relative to the suite file (never looked up in the worlds
folder).
"""

from __future__ import annotations

import difflib
from pathlib import Path

from arena.core.errors import ConfigError
from arena.core.names import RULE, name_problem
from arena.maps.sources import packaged_worlds, resolve_world, worlds_in


def _is_world(folder: Path) -> bool:
    return (folder / "map" / "map.yaml").is_file() or (folder / "map.yaml").is_file()


def find_stage_world(
    name: str, *, suite_file: Path, worlds: Path | None, origin: str = "--worlds"
) -> str:
    """The world folder (or packaged world name) a stage's ``map`` string names.

    Args:
        name: the stage's ``map``: a world name or a folder path with ``/``.
        suite_file: the suite file (paths and the folders next to it are relative to it).
        worlds: the worlds folder (checked to exist), or ``None``.
        origin: where ``worlds`` was given (``--worlds``, a file's key), for messages.

    Returns:
        A folder path, or a name :func:`~arena.maps.sources.resolve_world` resolves.

    Raises:
        ConfigError: a name that cannot be a folder name, or a world found nowhere (with the
            closest names of the worlds folder and the packaged worlds), without a source: the
            caller names the suite file and the key.
    """
    base = suite_file.resolve().parent
    is_path = "/" in name or "\\" in name
    if not is_path:
        problem = name_problem(name)
        if problem is not None:
            raise ConfigError(
                f"world name {name!r} {problem}: a world is named by its folder ({RULE}); a "
                "world folder elsewhere is a path with '/' (relative to the suite file)")
    folders = [] if is_path or worlds is None else [worlds / name]
    folders.append(base / name)
    if not is_path:
        folders += [base / "worlds" / name, base.parent / "worlds" / name]
    for folder in folders:
        if _is_world(folder):
            return str(folder)
    try:
        resolve_world(name)
    except ConfigError as e:
        if is_path:
            raise
        raise ConfigError(_not_found(name, e.message, worlds, origin)) from None
    return name


def _not_found(name: str, message: str, worlds: Path | None, origin: str) -> str:
    """The message for a world name found nowhere: close names of the worlds folder."""
    if worlds is None:
        return (f"{message}; Arena's suites name the worlds of arena-simulation-setup/worlds: "
                "give that folder with --worlds DIR")
    there = worlds_in(worlds)
    known = there + [w for w in packaged_worlds() if w not in there]
    close = difflib.get_close_matches(name, known, n=3, cutoff=0.6)
    hint = f"did you mean {', '.join(map(repr, close))}? " if close else ""
    if there:
        held = f"it holds {len(there)} world{'s' if len(there) > 1 else ''}"
    elif worlds_in(worlds / "worlds"):
        held = f"it holds no <world>/map/map.yaml; did you mean {worlds / 'worlds'}?"
    else:
        held = "it holds no <world>/map/map.yaml"
    return (f"no world {name!r} in the worlds folder {worlds} ({origin}; {held}), next to the "
            f"suite or packaged; {hint}packaged worlds: {', '.join(packaged_worlds())}")


__all__ = ["find_stage_world"]

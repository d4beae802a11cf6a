"""Procedural map generators: registry and shared helpers.

A generator is a map source (:class:`arena.maps.sources.MapSource`): ``build(rng)`` returns a
:class:`~arena.maps.sources.MapResult` with the occupancy grid and the obstacles it placed (real
footprints from :mod:`arena.maps.obstacles`). :func:`register_generator` puts it in
:data:`MAP_GENERATORS` and in :data:`~arena.maps.sources.MAP_SOURCES`, so a config selects it with
``map: {type: barn, fill_pct: 0.2}``. Every random draw comes from the ``rng`` argument.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from arena.core.registry import Registry
from arena.maps.sources import MAP_SOURCES, MapSource

MAP_GENERATORS: Registry[MapSource] = Registry("map generator", entry_points="arena.map_generators")


def register_generator(name: str, *, tags: tuple[str, ...] = ()) -> Callable[[Any], Any]:
    """Class decorator: register a generator under ``name`` in both registries."""

    def deco(cls: Any) -> Any:
        MAP_GENERATORS.add(name, cls, tags=tags)
        MAP_SOURCES.add(name, cls, tags=("generator", *tags))
        return cls

    return deco

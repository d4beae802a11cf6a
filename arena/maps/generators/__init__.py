"""Procedural map generators (registry :data:`MAP_GENERATORS`); importing registers them all."""

from arena.maps.generators import barn, rosmap, rosnav  # noqa: F401  (register the generators)
from arena.maps.generators.base import MAP_GENERATORS, register_generator

__all__ = ["MAP_GENERATORS", "register_generator"]

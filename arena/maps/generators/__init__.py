"""Procedural map generators (registry :data:`MAP_GENERATORS`); importing registers them all."""

import importlib

from arena.maps.generators.base import MAP_GENERATORS, register_generator

for _name in ("barn", "rosnav", "rosmap", "canteen", "warehouse", "office", "outdoor"):
    try:
        importlib.import_module(f"arena.maps.generators.{_name}")
    except ModuleNotFoundError as e:  # the rosmap family may live in one module or four
        if e.name != f"arena.maps.generators.{_name}":
            raise

__all__ = ["MAP_GENERATORS", "register_generator"]

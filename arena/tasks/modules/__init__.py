"""Task modules (``task.modules``): hooks around each reset (curricula, maps, benchmarks, UI)."""

from arena.tasks.modules import clear_forbidden_zones, dynamic_map  # noqa: F401

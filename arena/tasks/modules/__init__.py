"""Task modules (``task.modules``): hooks around each reset (curricula, maps, benchmarks, UI)."""

from arena.tasks.modules import (  # noqa: F401
    benchmark,
    clear_forbidden_zones,
    dynamic_map,
    interactive,
    staged,
)

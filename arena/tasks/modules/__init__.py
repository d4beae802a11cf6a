"""Task modules (``task.modules``): hooks around each reset (curricula, maps, benchmarks, UI).

Each module registers its mode on import; :data:`~arena.tasks.base.TASK_MODES` declares them
by name and imports one when a config first names it.
"""

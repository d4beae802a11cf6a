"""Obstacle task modes (``task.obstacles``): static obstacles and pedestrians of an episode.

Each module registers its mode on import; :data:`~arena.tasks.base.TASK_MODES` declares them
by name and imports one when a config first names it.
"""

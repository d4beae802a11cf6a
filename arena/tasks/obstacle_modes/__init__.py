"""Obstacle task modes (``task.obstacles``): static obstacles and pedestrians of an episode."""

from arena.tasks.obstacle_modes import parametrized, random, scenario, zones  # noqa: F401

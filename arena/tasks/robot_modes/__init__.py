"""Robot task modes (``task.robots``): where robots start and which goals they get."""

from arena.tasks.robot_modes import explore, guided, random, scenario, zones  # noqa: F401

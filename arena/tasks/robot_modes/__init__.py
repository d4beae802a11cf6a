"""Robot task modes (``task.robots``): where robots start and which goals they get.

Each module registers its mode on import; :data:`~arena.tasks.base.TASK_MODES` declares them
by name and imports one when a config first names it.
"""

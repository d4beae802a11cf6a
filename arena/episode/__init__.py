"""One episode, one loop: the runner with its hooks, and the navigation-stack controller.

Below ``experiment``, ``eval`` and ``learn``, above ``sim``, ``nav`` and ``tasks``: every path
that simulates an episode ticks an :class:`~arena.episode.runner.EpisodeRunner`.
"""

"""The ``native2d`` backend."""

from arena.sim.native2d.backend import Native2DBackend

__all__ = ["Native2DBackend"]

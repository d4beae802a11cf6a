"""Batched simulation: ``N`` independent single-robot worlds stepped in array operations.

See :mod:`arena.sim.batch.sim` for the design and how it differs from ``native2d``.
"""

from arena.sim.batch.kernels import KIND_NONE, KIND_OBSTACLE, KIND_PEDESTRIAN, KIND_WALL
from arena.sim.batch.sim import BatchCrowdParams, BatchSim, BatchState

__all__ = [
    "KIND_NONE",
    "KIND_OBSTACLE",
    "KIND_PEDESTRIAN",
    "KIND_WALL",
    "BatchCrowdParams",
    "BatchSim",
    "BatchState",
]

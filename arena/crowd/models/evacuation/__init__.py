"""Escape panic: Helbing, Farkas & Vicsek's social force model (registered as ``evacuation``).

:mod:`.model` holds the parameters, the :class:`Evacuation` class, the sub-step memory, the
wall segments and the documentation; :mod:`.kernels` the numba kernels (stiffness bounds and
the sub-stepped integration).
"""

from arena.crowd.models.evacuation.model import (
    TERMS,
    Evacuation,
    SegmentWalls,
    SubstepMemory,
    substeps,
)

__all__ = ["TERMS", "Evacuation", "SegmentWalls", "SubstepMemory", "substeps"]

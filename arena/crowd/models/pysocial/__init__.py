"""PySocialForce's extended social force model, Arena's default crowd (registered as ``pysocial``).

:mod:`.model` holds the parameters, the :class:`PySocialModel` class and the documentation of
the forces; the numba kernels are in :mod:`.kernels` (per-agent terms and the total),
:mod:`.pair_kernels` (the social term, pair by pair) and :mod:`.obstacle_kernels` (the wall
points).
"""

from arena.crowd.models.pysocial.model import (
    TERMS,
    PySocialModel,
    desired_force,
    group_members,
    sample_segments,
)

__all__ = ["TERMS", "PySocialModel", "desired_force", "group_members", "sample_segments"]

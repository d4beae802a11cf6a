"""ORCA (RVO2's optimal reciprocal collision avoidance), registered as ``orca``.

:mod:`.model` holds the parameters, the :class:`OrcaModel` class and the documentation;
:mod:`.kernels` RVO2's neighbour search and linear programs in numba; :mod:`.obstacles` the
static obstacles in RVO2's representation (also used by :mod:`arena.crowd.models.rvo2`).
"""

from arena.crowd.models.orca.kernels import RVO_EPSILON, orca_kernel
from arena.crowd.models.orca.model import (
    FloatArray,
    OrcaModel,
    OrcaParams,
    orca_velocities,
    preferred_velocities,
)
from arena.crowd.models.orca.obstacles import Obstacles

__all__ = [
    "RVO_EPSILON",
    "FloatArray",
    "Obstacles",
    "OrcaModel",
    "OrcaParams",
    "orca_kernel",
    "orca_velocities",
    "preferred_velocities",
]

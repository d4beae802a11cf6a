"""libpedsim's social force model as Arena's pedsim simulator runs it (``pedsim``, ``passthrough``).

:mod:`.model` holds the parameters, the :class:`PedsimModel` class and the documentation of the
terms; :mod:`.kernels` the numba kernels (social pairs in SIMD batches, per-agent terms).
"""

from arena.crowd.models.pedsim.model import TERMS, PassthroughModel, PedsimModel

__all__ = ["TERMS", "PassthroughModel", "PedsimModel"]

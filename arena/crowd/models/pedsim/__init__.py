"""libpedsim's social force model as Arena's pedsim simulator runs it (``pedsim``, ``passthrough``).

:mod:`.params` holds the parameters; :mod:`.model` the :class:`PedsimModel` class and the
documentation of the terms; :mod:`.kernels` the numba kernels (social pairs in SIMD batches, per-
agent terms).

The package imports nothing: a config validates :mod:`.params` without compiling the kernels.
"""

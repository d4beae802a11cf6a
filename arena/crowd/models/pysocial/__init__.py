"""PySocialForce's extended social force model, Arena's default crowd (registered as ``pysocial``).

:mod:`.params` holds the parameters; :mod:`.model` the :class:`PySocialModel` class and the
documentation of the forces; the numba kernels are in :mod:`.kernels` (per-agent terms and the
total), :mod:`.pair_kernels` (the social term, pair by pair) and :mod:`.obstacle_kernels` (the wall
points).

The package imports nothing: a config validates :mod:`.params` without compiling the kernels.
"""

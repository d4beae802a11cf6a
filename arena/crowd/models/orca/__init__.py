"""ORCA (RVO2's optimal reciprocal collision avoidance), registered as ``orca``.

:mod:`.params` holds the parameters; :mod:`.model` the :class:`OrcaModel` class and the
documentation; :mod:`.kernels` RVO2's neighbour search and linear programs in numba;
:mod:`.obstacles` the static obstacles in RVO2's representation (also used by
:mod:`arena.crowd.models.rvo2`).

The package imports nothing: a config validates :mod:`.params` without compiling the kernels.
"""

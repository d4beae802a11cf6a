"""Escape panic: Helbing, Farkas & Vicsek's social force model (registered as ``evacuation``).

:mod:`.params` holds the parameters; :mod:`.model` the :class:`Evacuation` class, the sub-step
memory, the wall segments and the documentation; :mod:`.kernels` the numba kernels (stiffness
bounds and the sub-stepped integration).

The package imports nothing: a config validates :mod:`.params` without compiling the kernels.
"""

"""The batched env's fast social force as an ordinary crowd model (``fast_social_force``).

:mod:`.params` holds the parameters; :mod:`.model` the :class:`FastSocialForceModel` and its
:class:`FastSocialForceDriver` (a whole pedestrian driver, not a model inside the crowd
simulator) with the documentation; :mod:`.kernels` the one-world numba step.

The package imports nothing: a config validates :mod:`.params` without compiling the kernels.
"""

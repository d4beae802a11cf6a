"""The built-in crowd models; importing this package registers them all."""

from arena.crowd.models import (  # noqa: F401  (each module registers its models)
    bonding,
    deep_social_force,
    evacuation,
    orca,
    pedsim,
    pysocial,
    rvo2,
    spinny,
    walker,
)

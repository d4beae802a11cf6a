"""Crowd models: what moves the pedestrians.

The simulator sees pedestrians only through :class:`arena.sim.backend.PedestrianDriver`; every
entry of :data:`CROWD_MODELS` builds one. The crowd issue's social-force family, ORCA and the
social states plug in here without the backends changing.
"""

from __future__ import annotations

from arena.core.registry import Registry
from arena.sim.backend import PedestrianDriver

CROWD_MODELS: Registry[PedestrianDriver] = Registry(
    "crowd model", entry_points="arena.crowd_models"
)

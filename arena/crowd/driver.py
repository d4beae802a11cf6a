"""The pedestrian driver of a config: one function for every place that runs episodes.

Most crowd models compute accelerations (or velocities) inside the
:class:`~arena.crowd.simulator.CrowdSimulator`, which adds social states, groups, start-up
modes and the shared integrator; a :class:`~arena.crowd.base.DriverModel` moves its pedestrians
itself. :func:`build_driver` returns whichever the ``crowd:`` block names.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from arena.crowd.base import CROWD_MODELS, CrowdModel, DriverModel
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig

if TYPE_CHECKING:
    from arena.sim.backend import PedestrianDriver


def build_driver(
    crowd: dict[str, Any] | str, pedestrians: PedestrianConfig | None = None
) -> PedestrianDriver:
    """The driver for the config's ``crowd:`` block (the model) and ``pedestrians:`` block.

    Raises:
        ConfigError: naming ``crowd.<key>`` when the block is invalid.
    """
    return driver_of(CROWD_MODELS.build(crowd, path="crowd"), pedestrians)


def driver_of(
    model: CrowdModel | DriverModel, pedestrians: PedestrianConfig | None = None
) -> PedestrianDriver:
    """``model``'s own driver if it is a :class:`DriverModel`, else a crowd simulator of it."""
    if isinstance(model, DriverModel):
        return model.make_driver(pedestrians)
    return CrowdSimulator(model, pedestrians)

"""Pedestrian simulation: crowd models behind one registry, social states, semantic layers.

The :class:`~arena.crowd.simulator.CrowdSimulator` is what the simulator backends call; the
motion model inside it comes from :data:`CROWD_MODELS`.
"""

from arena.crowd import models as _models  # noqa: F401  (registers the built-in models)
from arena.crowd.base import CROWD_MODELS, CrowdFrame, CrowdModel, ModelOutput, RobotView
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig
from arena.crowd.state import AgentType, CrowdState, SocialState, StartupMode

__all__ = [
    "CROWD_MODELS",
    "AgentType",
    "CrowdFrame",
    "CrowdModel",
    "CrowdSimulator",
    "CrowdState",
    "ModelOutput",
    "PedestrianConfig",
    "RobotView",
    "SocialState",
    "StartupMode",
]

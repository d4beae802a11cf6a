"""The one simulation engine: ``W`` worlds through crowd, kinematics, contacts and sensors.

See :mod:`arena.sim.engine.engine`.
"""

from arena.sim.engine.agents import PaddedAgents
from arena.sim.engine.engine import Engine
from arena.sim.engine.params import EngineParams
from arena.sim.engine.scene import DynamicScene

__all__ = ["DynamicScene", "Engine", "EngineParams", "PaddedAgents"]

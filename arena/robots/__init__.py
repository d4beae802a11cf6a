"""Robots: kinematics models, the :class:`RobotModel` data model and the built-in presets.

Presets are YAML data (``arena/robots/presets/*.yaml``): the 14 Arena-Rosnav robots and the
car-like ``f1tenth``. Load one with :func:`load_robot`; list them with :func:`robot_names` or,
as table rows, :func:`describe_robots`.
"""

from arena.robots.kinematics import KINEMATICS, Kinematics, KinematicState
from arena.robots.limits import VelocityLimits
from arena.robots.model import RobotModel
from arena.robots.presets import ROBOTS, describe_robots, load_robot, robot_names

__all__ = [
    "KINEMATICS",
    "ROBOTS",
    "KinematicState",
    "Kinematics",
    "RobotModel",
    "VelocityLimits",
    "describe_robots",
    "load_robot",
    "robot_names",
]

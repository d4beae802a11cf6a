"""Robot kinematics models, one registry (:data:`KINEMATICS`) and their shared contract.

Importing this package registers the built-in models: ``diff_drive``, ``omni``, ``ackermann``
and ``legged``. Third-party models arrive through the ``arena.kinematics`` entry-point group.
"""

from arena.robots.kinematics.ackermann import AckermannKinematics
from arena.robots.kinematics.base import KINEMATICS, Kinematics, KinematicState, integrate_twist
from arena.robots.kinematics.diff_drive import DiffDriveKinematics
from arena.robots.kinematics.legged import LeggedKinematics
from arena.robots.kinematics.omni import OmniKinematics

__all__ = [
    "KINEMATICS",
    "AckermannKinematics",
    "DiffDriveKinematics",
    "KinematicState",
    "Kinematics",
    "LeggedKinematics",
    "OmniKinematics",
    "integrate_twist",
]

"""Sensors: specifications and the fast 2-D lidar."""

from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarSpec

__all__ = ["Lidar2D", "LidarSpec"]

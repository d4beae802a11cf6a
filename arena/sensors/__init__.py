"""Sensors: the registry of sensor types, specifications and the fast 2-D lidar."""

from arena.sensors.base import SENSORS, SensorBank
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarReading, LidarSpec, lidar_geometry

__all__ = ["SENSORS", "Lidar2D", "LidarReading", "LidarSpec", "SensorBank", "lidar_geometry"]

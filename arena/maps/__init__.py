"""Occupancy-grid maps and their ROS ``map_server`` files (``map.yaml`` + PGM/PNG image)."""

from arena.maps.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from arena.maps.io import MapMetadata, load_map, load_map_with_metadata, save_map

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "MapMetadata",
    "OccupancyGrid",
    "load_map",
    "load_map_with_metadata",
    "save_map",
]

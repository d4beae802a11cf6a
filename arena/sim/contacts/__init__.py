"""Exact-footprint contacts of robots with walls, obstacles, pedestrians and each other.

Walls are also tested along each move (the tunnelling sweep); one robot at a time
(:func:`hits_grid` ...) or every robot of every world in one call (:class:`ContactBank`).
"""

from arena.sim.contacts.bank import ContactBank, ContactFlags
from arena.sim.contacts.checks import (
    first_agent_hit,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)
from arena.sim.contacts.footprint import Footprint, ObstacleIndex

__all__ = [
    "ContactBank",
    "ContactFlags",
    "Footprint",
    "ObstacleIndex",
    "first_agent_hit",
    "first_obstacle_hit",
    "footprints_overlap",
    "hits_grid",
]

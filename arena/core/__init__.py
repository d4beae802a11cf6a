"""Core types, the plugin registry, typed errors, seeded RNG splitting and geometry helpers."""

from arena.core.errors import (
    ArenaError,
    ConfigError,
    GoalOccupied,
    MapError,
    NoPathFound,
    PlanningError,
    SamplingError,
    SimulationError,
    StartOccupied,
    UnknownNameError,
)
from arena.core.registry import Registry, all_registries
from arena.core.rng import child_seed, derive_rng
from arena.core.types import Outcome, Pose2D, Twist

__all__ = [
    "ArenaError",
    "ConfigError",
    "GoalOccupied",
    "MapError",
    "NoPathFound",
    "Outcome",
    "PlanningError",
    "Pose2D",
    "Registry",
    "SamplingError",
    "SimulationError",
    "StartOccupied",
    "Twist",
    "UnknownNameError",
    "all_registries",
    "child_seed",
    "derive_rng",
]

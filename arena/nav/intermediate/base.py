"""The intermediate-planner interface, its input/output types, registry and shared helpers.

An intermediate ("inter") planner sits between the global planner and the local planner
(Arena-Rosnav's move_base_flex *inter* plugins, arena_specs §7): it receives the global path
and the pedestrians around the robot, and returns

- the path the local planner should follow now (the global path, a subsampled piece of it, or a
  short detour such as a temporary goal behind the robot), and
- overrides of local-planner parameters (e.g. ``{"max_speed": 0.3}`` m/s), which the navigation
  stack applies to the local planner when it has a parameter or attribute of that name.

Planners may keep state between calls (a temporary goal, a timer); :meth:`IntermediatePlanner.
reset` clears it. Inputs are never modified.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from arena.core.registry import Registry

if TYPE_CHECKING:  # the costmap package is optional for intermediate planners
    from arena.nav.costmap import Costmap

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

ELDER = 1
"""Pedestrian type code of an elder (``AgentType.ELDER``; Arena's ``human/elder``)."""


def _empty2() -> FloatArray:
    return np.zeros((0, 2), dtype=np.float64)


def _empty_int() -> IntArray:
    return np.zeros(0, dtype=np.int64)


@dataclass(frozen=True, eq=False)
class Pedestrians:
    """The pedestrians an intermediate planner knows about (world frame).

    Attributes:
        positions: ``(n, 2)`` m.
        velocities: ``(n, 2)`` m/s.
        kinds: ``(n,)`` type codes (0 adult, 1 elder, 2 child), or ``(0,)`` when unknown.
        states: ``(n,)`` social-state codes (:class:`arena.crowd.state.SocialState`), or
            ``(0,)`` when unknown.
    """

    positions: FloatArray = field(default_factory=_empty2)
    velocities: FloatArray = field(default_factory=_empty2)
    kinds: IntArray = field(default_factory=_empty_int)
    states: IntArray = field(default_factory=_empty_int)

    def __len__(self) -> int:
        return int(np.asarray(self.positions).reshape(-1, 2).shape[0])


@dataclass(frozen=True, eq=False)
class IntermediateInput:
    """Everything an intermediate planner sees at one call.

    Attributes:
        pose: ``(3,)`` robot pose ``[x m, y m, theta rad]``, world frame.
        twist: ``(3,)`` body twist ``[vx m/s, vy m/s, omega rad/s]``.
        path: ``(k, 2)`` global path (m, world frame), first point near the robot.
        goal: ``(3,)`` navigation goal ``[x m, y m, theta rad]``.
        max_speed: the local planner's nominal cruise speed (m/s): what "full speed" means for
            the speed overrides.
        robot_radius: radius of the robot's bounding circle (m).
        pedestrians: pedestrians around the robot (may be empty).
        obstacle_points: ``(m, 2)`` laser returns in the world frame (m); may be empty.
        window: size of the local window (m): the radius around the robot that the local
            planner (costmap) looks at.
        time: simulation time (s).
        global_costmap, local_costmap: the stack's costmaps (``costmap_2d`` costs) when
            ``navigation.global_costmap`` / ``navigation.local_costmap`` are configured, else
            ``None``; planners that use them must cope with ``None``.
    """

    pose: FloatArray
    twist: FloatArray
    path: FloatArray
    goal: FloatArray
    max_speed: float
    robot_radius: float
    pedestrians: Pedestrians = field(default_factory=Pedestrians)
    obstacle_points: FloatArray = field(default_factory=_empty2)
    window: float = 5.0
    time: float = 0.0
    global_costmap: Costmap | None = None
    local_costmap: Costmap | None = None


@dataclass(frozen=True, eq=False)
class IntermediateOutput:
    """What an intermediate planner hands to the local planner.

    Attributes:
        path: ``(m, 2)`` path to follow now (m, world frame); ``m ≥ 1`` unless the global path
            itself is empty.
        overrides: local-planner parameter overrides, e.g. ``{"max_speed": 0.3}`` (m/s). An
            empty dict means "the configured values".
        info: diagnostics (``danger`` in [0, 1], ``mode`` …); not used by the stack.
    """

    path: FloatArray
    overrides: dict[str, float] = field(default_factory=dict)
    info: dict[str, float | str] = field(default_factory=dict)


@runtime_checkable
class IntermediatePlanner(Protocol):
    """Refines the global path and tunes the local planner from a wider view."""

    def reset(self) -> None:
        """Forget all internal state (call at every episode start)."""
        ...

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """Return the path to follow and parameter overrides for this call; ``inp`` unchanged."""
        ...


INTERMEDIATE_PLANNERS: Registry[IntermediatePlanner] = Registry(
    "intermediate planner", entry_points="arena.intermediate_planners"
)


# -- helpers shared by the social planners ----------------------------------------------------
def pedestrian_distances(inp: IntermediateInput) -> FloatArray:
    """``(n,)`` distances (m) from the robot to each pedestrian.

    Arena computes ``sqrt(dx² + dy²) + dz²``; in the plane ``dz = 0``, so this is Euclidean.
    """
    peds = np.asarray(inp.pedestrians.positions, dtype=np.float64).reshape(-1, 2)
    xy = np.asarray(inp.pose, dtype=np.float64).reshape(3)[:2]
    return np.asarray(np.hypot(peds[:, 0] - xy[0], peds[:, 1] - xy[1]), dtype=np.float64)


def danger_level(distances: FloatArray) -> float:
    """Arena's danger signal ``exp(−1 / Σ_i (3 / d_i)²)`` in [0, 1] (0 without pedestrians)."""
    d = np.maximum(np.asarray(distances, dtype=np.float64), 1e-9)
    if d.size == 0:
        return 0.0
    return float(math.exp(-1.0 / float(np.sum((3.0 / d) ** 2))))


def in_fov(inp: IntermediateInput, targets: FloatArray, fov: float) -> NDArray[np.bool_]:
    """Which points ``(n, 2)`` lie in the cone of full width ``fov`` (rad) around the heading.

    Arena computes the bearing as ``atan2(dx, dy)`` (x and y swapped), which measures from the
    wrong axis; we use the intended ``atan2(dy, dx)`` so that "in front" means in front.
    """
    q = np.asarray(inp.pose, dtype=np.float64).reshape(3)
    t = np.asarray(targets, dtype=np.float64).reshape(-1, 2)
    bearing = np.arctan2(t[:, 1] - q[1], t[:, 0] - q[0]) - q[2]
    rel = np.abs((bearing + np.pi) % (2 * np.pi) - np.pi)
    return np.asarray(2.0 * rel <= fov + 1e-12)


def detour_path(inp: IntermediateInput, target: FloatArray) -> FloatArray:
    """The two-point path ``[robot position, target]`` (m)."""
    xy = np.asarray(inp.pose, dtype=np.float64).reshape(3)[:2]
    return np.vstack([xy, np.asarray(target, dtype=np.float64).reshape(2)])

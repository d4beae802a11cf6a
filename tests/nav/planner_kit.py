"""Shared fixtures for the local-planner tests.

Velocity limits per drive, observations, straight paths, one integration step and synthetic
laser scans of a wall and a round post.
"""

from __future__ import annotations

import math

import numpy as np

from arena.core.types import Pose2D
from arena.nav.local_planners import LocalObservation
from arena.robots.kinematics import integrate_twist
from arena.robots.limits import VelocityLimits
from arena.testing.local_planner import random_twist

DT = 0.1
RADIUS = 0.3
DIFF = VelocityLimits(0.0, 1.0, 0.0, 0.0, 1.5, 1.0, 0.0, 3.0)
OMNI = VelocityLimits(-0.8, 0.8, -0.6, 0.6, 1.2, 1.0, 1.0, 2.0)
CAR = VelocityLimits(0.0, 1.5, 0.0, 0.0, 1.5, 1.0, 0.0, 2.0, min_turning_radius=1.2)
LEGGED = VelocityLimits(-0.3, 0.7, 0.0, 0.0, 1.0, 0.8, 0.0, 2.0)
DRIVES = {"diff_drive": DIFF, "omni": OMNI, "ackermann": CAR, "legged": LEGGED}


def obs(pose, path, twist=(0.0, 0.0, 0.0), limits=DIFF, kin="diff_drive", ranges=None,
        angles=None) -> LocalObservation:
    path = np.asarray(path, dtype=float)
    return LocalObservation(
        pose=np.asarray(pose, dtype=float), twist=np.asarray(twist, dtype=float),
        goal=Pose2D(*path[-1]), path=path, limits=limits, robot_radius=RADIUS, dt=DT,
        scan_ranges=np.zeros(0) if ranges is None else np.asarray(ranges, dtype=float),
        scan_angles=np.zeros(0) if angles is None else np.asarray(angles, dtype=float),
        kinematics=kin,
    )


def line(x0: float, x1: float, n: int = 50) -> np.ndarray:
    return np.stack([np.linspace(x0, x1, n), np.zeros(n)], axis=-1)


def step(pose: np.ndarray, cmd: np.ndarray) -> np.ndarray:
    return integrate_twist(pose[None, :], cmd[None, :], DT)[0]


def wall_scan(pose: np.ndarray, wall_x: float, n: int = 360) -> tuple[np.ndarray, np.ndarray]:
    """Ranges of a wall ``x = wall_x`` (world) seen from ``pose``, 8 m max range."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    world = angles + pose[2]
    with np.errstate(divide="ignore"):
        t = (wall_x - pose[0]) / np.cos(world)
    return np.where((t > 0) & (t < 8.0), t, np.inf), angles


def post_scan(pose: np.ndarray, centre: np.ndarray, radius: float,
               n: int = 360) -> tuple[np.ndarray, np.ndarray]:
    """Ranges of a round post (world ``centre``, ``radius``) seen from ``pose``."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    d = np.stack([np.cos(angles + pose[2]), np.sin(angles + pose[2])], axis=-1)
    rel = centre - pose[:2]
    b = d @ rel
    disc = b * b - (rel @ rel - radius * radius)
    t = b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (t > 0), t, np.inf), angles


def random_case(
    rng: np.random.Generator, lim: VelocityLimits, kin: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A random admissible twist, pose, 4-point path and 90-beam scan for drive ``kin``."""
    twist = random_twist(rng, lim, kin)
    pose = rng.uniform([-1, -1, -3], [1, 1, 3])
    path = np.vstack([pose[:2], pose[:2] + rng.normal(0, 2, (3, 2)).cumsum(axis=0)])
    ranges = rng.uniform(0.4, 5.0, 90)
    angles = np.linspace(-math.pi, math.pi, 90, endpoint=False)
    return twist, pose, path, ranges, angles


def assert_within_limits(cmd: np.ndarray, twist: np.ndarray, lim: VelocityLimits, kin: str) -> None:
    """``cmd`` lies in the velocity box and one step's acceleration from ``twist``; car-like
    robots keep ``|ω| ≤ |v| / r_min`` instead of the yaw-acceleration bound."""
    room = lim.acceleration * DT + 1e-9
    assert np.all(cmd >= lim.lower - 1e-9) and np.all(cmd <= lim.upper + 1e-9)
    assert abs(cmd[0] - twist[0]) <= room[0] and abs(cmd[1] - twist[1]) <= room[1]
    if kin == "ackermann":
        assert abs(cmd[2]) <= abs(cmd[0]) / lim.min_turning_radius + 1e-9
    else:
        assert abs(cmd[2] - twist[2]) <= room[2]


BEHIND_ASIDE = np.array([[0.0, 0.0], [-1.0, 2.0], [-3.0, 2.5]])
"""A path to a goal behind and to the left of a robot at the origin facing +x."""


def drive(planner, path: np.ndarray, kin: str, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Run ``planner`` closed loop from the origin at rest for ``steps`` ticks (ideal robot)."""
    lim = DRIVES[kin]
    pose, twist = np.array([0.0, 0.0, 0.0]), np.zeros(3)
    for _ in range(steps):
        cmd = planner.compute(obs(pose, path, twist, lim, kin))
        pose, twist = step(pose, cmd), cmd
    return pose, twist

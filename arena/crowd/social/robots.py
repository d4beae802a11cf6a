"""How pedestrians react to robots: fear (stress) and the Table II avoidance push, vectorised.

Both are dense over ``(agents, robots)``: robots are few, so an ``(n, r)`` array is cheap.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import RobotView
from arena.crowd.social.params import RobotAvoidanceParams

FloatArray = NDArray[np.float64]


def robot_fear(
    positions: FloatArray,
    personal_space_radius: FloatArray,
    fear_robot: FloatArray,
    speed_tolerance: FloatArray,
    robots: RobotView,
) -> FloatArray:
    """Arena's per-tick stress from robots inside each agent's personal space.

    Each robot whose centre is strictly closer than ``personal_space_radius`` adds
    ``fear_robot + max(0, ‖v_robot‖ − speed_tolerance)``; contributions of several robots add.

    Args:
        positions: ``(n, 2)`` m.
        personal_space_radius: ``(n,)`` m.
        fear_robot: ``(n,)`` stress per tick.
        speed_tolerance: ``(n,)`` m/s.
        robots: the robots (world-frame velocities).

    Returns:
        ``(n,)`` stress per Arena tick (the caller turns it into a rate).
    """
    n = positions.shape[0]
    if n == 0 or len(robots) == 0:
        return np.zeros(n)
    d = positions[:, None, :] - np.asarray(robots.positions)[None, :, :]
    inside = np.hypot(d[..., 0], d[..., 1]) < personal_space_radius[:, None]
    v = np.asarray(robots.velocities).reshape(-1, 2)
    speed = np.hypot(v[:, 0], v[:, 1])
    excess = np.maximum(0.0, speed[None, :] - speed_tolerance[:, None])
    fear: FloatArray = np.where(inside, fear_robot[:, None] + excess, 0.0).sum(axis=1)
    return fear


def robot_avoidance(
    positions: FloatArray,
    radii: FloatArray,
    personal_space_radius: FloatArray,
    robots: RobotView,
    params: RobotAvoidanceParams,
) -> FloatArray:
    """``(n, 2)`` m/s², exponential repulsion from every robot (see RobotAvoidanceParams).

    Args:
        positions: ``(n, 2)`` m.
        radii: ``(n,)`` m, agent body radii.
        personal_space_radius: ``(n,)`` m, sets each agent's decay length and cutoff.
        robots: the robots (circumscribed radii).
        params: strength, decay and cutoff.
    """
    n = positions.shape[0]
    out = np.zeros((n, 2))
    if n == 0 or len(robots) == 0:
        return out
    psr = personal_space_radius[:, None]
    d = positions[:, None, :] - np.asarray(robots.positions)[None, :, :]
    dist = np.hypot(d[..., 0], d[..., 1])
    # Clearance between the circles; overlap counts as contact so the push stays bounded.
    gap = np.maximum(dist - radii[:, None] - np.asarray(robots.radii)[None, :], 0.0)
    mag = np.where(
        gap < params.cutoff_factor * psr,
        params.strength * np.exp(-gap / (params.range_factor * psr)),
        0.0,
    )
    unit = np.divide(d, dist[..., None], out=np.zeros_like(d), where=dist[..., None] > 0)
    push: FloatArray = (mag[..., None] * unit).sum(axis=1)
    return push

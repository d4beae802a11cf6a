"""The joint state of CrowdNav's value policies and its agent-centred rotation.

CrowdNav (Chen et al. 2019) describes the robot by its full state
``[px, py, vx, vy, radius, gx, gy, v_pref, theta]`` and each human by the observable state
``[px, py, vx, vy, radius]`` (world frame, m, m/s, rad). Before the value network sees a
(robot, human) pair, :func:`rotate` moves it into the frame centred on the robot with ``x``
toward the goal, which makes the value invariant to global rotations and translations:

- self part (6): ``[dg, v_pref, theta', radius, vx', vy']``: goal distance, preferred speed,
  heading relative to the goal direction (unicycle robots; 0 for holonomic ones), radius,
  velocity in the goal frame;
- human part (7): ``[px1', py1', vx1', vy1', radius1, da, radius_sum]``: the human's position
  and velocity in the goal frame, radius, distance to the robot and the sum of both radii.

Our choices where CrowdNav leaves none: ``theta'`` is wrapped to ``[-π, π)`` (CrowdNav leaves it
unwrapped, which makes equal headings look different after a few turns); humans are the
``max_humans`` nearest within ``human_range`` m; and when none is, a single *phantom* human
(:data:`PHANTOM_DISTANCE` m behind the robot, standing still) stands in, because both networks
need at least one pair. Training and inference build the state with the same function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

SELF_DIM = 6
"""Length of the rotated self part."""
HUMAN_DIM = 7
"""Length of the rotated human part."""
PAIR_DIM = SELF_DIM + HUMAN_DIM
"""Length of one rotated (robot, human) pair: 13."""
ROBOT_DIM = 9
"""Length of the robot's full state ``[px, py, vx, vy, radius, gx, gy, v_pref, theta]``."""
OBSERVABLE_DIM = 5
"""Length of a human's observable state ``[px, py, vx, vy, radius]``."""
PHANTOM_DISTANCE = 10.0
"""m, distance behind the robot of the phantom human used when no human is in range."""


def _wrap(a: FloatArray) -> FloatArray:
    return (a + np.pi) % (2 * np.pi) - np.pi


@dataclass(frozen=True, eq=False)
class JointState:
    """The robot's full state and the observable states of the humans it considers.

    Attributes:
        robot: ``(9,)`` ``[px m, py m, vx m/s, vy m/s, radius m, gx m, gy m, v_pref m/s,
            theta rad]``, world frame.
        humans: ``(n ≥ 1, 5)`` ``[px m, py m, vx m/s, vy m/s, radius m]``, world frame
            (the phantom human when none is in range).
    """

    robot: FloatArray
    humans: FloatArray


def joint_state(
    pose: FloatArray,
    velocity: FloatArray,
    radius: float,
    goal: FloatArray,
    v_pref: float,
    pedestrians: FloatArray,
    human_radius: float,
    human_range: float,
    max_humans: int,
) -> JointState:
    """The joint state of a robot among pedestrians.

    Args:
        pose: ``(3,)`` robot pose ``[x m, y m, theta rad]`` (world).
        velocity: ``(2,)`` robot velocity (m/s, world frame).
        radius: robot radius (m).
        goal: ``(2,)`` the (local) goal (m, world).
        v_pref: preferred speed (m/s).
        pedestrians: ``(n, 4)`` ``[x, y, vx, vy]`` (m, m/s, world).
        human_radius: radius given to every pedestrian (m).
        human_range: m, pedestrians farther than this (centre to centre) are left out.
        max_humans: at most this many, the nearest, are kept.
    """
    q = np.asarray(pose, dtype=np.float64).reshape(3)
    g = np.asarray(goal, dtype=np.float64).reshape(2)
    v = np.asarray(velocity, dtype=np.float64).reshape(2)
    robot = np.array([q[0], q[1], v[0], v[1], radius, g[0], g[1], v_pref, q[2]])
    peds = np.asarray(pedestrians, dtype=np.float64).reshape(-1, 4)
    d = np.hypot(peds[:, 0] - q[0], peds[:, 1] - q[1])
    order = np.argsort(d, kind="stable")
    order = order[d[order] <= human_range][:max_humans]
    if order.size:
        sel = peds[order]
        humans = np.column_stack([sel, np.full(len(sel), human_radius)])
    else:
        to_goal = g - q[:2]
        n = float(np.hypot(to_goal[0], to_goal[1]))
        u = to_goal / n if n > 1e-9 else np.array([math.cos(q[2]), math.sin(q[2])])
        p = q[:2] - PHANTOM_DISTANCE * u
        humans = np.array([[p[0], p[1], 0.0, 0.0, human_radius]])
    return JointState(robot=robot, humans=humans)


def rotate(robot: FloatArray, humans: FloatArray, holonomic: bool) -> FloatArray:
    """Rotated (robot, human) pairs, CrowdNav's ``rotate``; broadcasts over leading axes.

    Args:
        robot: ``(..., 9)`` full robot states (see :class:`JointState`).
        humans: ``(..., n, 5)`` observable human states, same leading axes as ``robot``
            (or broadcastable to them).
        holonomic: True: ``theta'`` is 0 (CrowdNav's holonomic robots); False: the heading
            relative to the goal direction, wrapped to ``[-π, π)``.

    Returns:
        ``(..., n, 13)``: ``[dg, v_pref, theta', radius, vx', vy', px1', py1', vx1', vy1',
        radius1, da, radius_sum]`` per pair.
    """
    r = np.asarray(robot, dtype=np.float64)[..., None, :]  # (..., 1, 9)
    h = np.asarray(humans, dtype=np.float64)
    px, py, vx, vy, rad = r[..., 0], r[..., 1], r[..., 2], r[..., 3], r[..., 4]
    gx, gy, vp, th = r[..., 5], r[..., 6], r[..., 7], r[..., 8]
    dx, dy = gx - px, gy - py
    rot = np.arctan2(dy, dx)
    c, s = np.cos(rot), np.sin(rot)
    dg = np.hypot(dx, dy)
    theta = np.zeros_like(th) if holonomic else _wrap(th - rot)
    hx, hy = h[..., 0] - px, h[..., 1] - py
    hvx, hvy = h[..., 2], h[..., 3]
    out = np.broadcast_arrays(
        dg, vp, theta, rad,
        vx * c + vy * s, vy * c - vx * s,
        hx * c + hy * s, hy * c - hx * s,
        hvx * c + hvy * s, hvy * c - hvx * s,
        h[..., 4], np.hypot(hx, hy), rad + h[..., 4],
    )
    return np.stack(out, axis=-1)

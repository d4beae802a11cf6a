"""Pedestrians as human figures, and the pure function that poses them while they walk.

A figure is three mocap bodies: ``person/<id>`` (torso, head, arms) and the two legs
``person/<id>/leg_l`` and ``/leg_r``, each hanging from its hip joint. The backend calls
:func:`pose_figures` each step with the crowd's positions, headings, distances walked and speeds
and writes the result into ``MjData.mocap_pos`` / ``mocap_quat``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.crowd.state import AgentType
from arena.sim.mujoco.scene import Body, Geom

HIP_FRACTION = 0.53
"""Hip joint height as a fraction of the stature."""


@dataclass(frozen=True)
class FigureSize:
    """Body measures of one kind of pedestrian (m)."""

    height: float
    shoulder: float
    """half the shoulder width"""
    leg_radius: float
    clothes: str
    """material of the torso"""

    @property
    def hip(self) -> float:
        """Hip joint height (m): about 0.53 of the stature."""
        return HIP_FRACTION * self.height

    @property
    def head_radius(self) -> float:
        """Head radius (m): a head is about 1/7.5 of the stature tall."""
        return self.height / 15.0


SIZES: dict[int, FigureSize] = {
    AgentType.ADULT: FigureSize(1.75, 0.21, 0.065, "adult"),
    AgentType.ELDER: FigureSize(1.65, 0.20, 0.065, "elder"),
    AgentType.CHILD: FigureSize(1.20, 0.14, 0.045, "child"),
}
"""Figure sizes by :class:`~arena.crowd.state.AgentType` code; other codes are drawn as adults."""

MAX_SWING = 0.45
"""rad, the largest leg swing (either way from vertical), reached when running."""
SWING_PER_SPEED = 0.3
"""rad per m/s: a walk at 1.3 m/s swings the legs about ±0.39 rad (±22°)."""
HIP_HALF_WIDTH = 0.09
"""m, hip joint offset from the body's centre line."""


def figure_size(kind: int) -> FigureSize:
    """The size of a person of type ``kind`` (adults for codes without a size of their own)."""
    return SIZES.get(int(kind), SIZES[AgentType.ADULT])


_CODES = np.array(sorted(SIZES), dtype=np.int64)
_HEIGHTS = np.array([SIZES[int(k)].height for k in _CODES])


def statures(kinds: ArrayLike) -> NDArray[np.float64]:
    """``(n,)`` m, the height of each person type code (:func:`figure_size`, vectorised)."""
    k = np.asarray(kinds, dtype=np.int64).reshape(-1)
    at = np.searchsorted(_CODES, k).clip(0, len(_CODES) - 1)
    return np.where(_CODES[at] == k, _HEIGHTS[at], SIZES[AgentType.ADULT].height)


def figure_bodies(person_id: int, kind: int, x: float, y: float, heading: float) -> list[Body]:
    """The three mocap bodies of one pedestrian standing at ``(x, y)`` facing ``heading``."""
    s = figure_size(kind)
    name = f"person/{person_id}"
    torso_top = 0.82 * s.height
    torso = (s.hip + torso_top) / 2
    arm_half = (torso_top - s.hip) / 2
    upper = (
        Geom(f"{name}/torso", "ellipsoid", (0.11, s.shoulder, (torso_top - s.hip) / 2 + 0.04),
             (0.0, 0.0, torso), s.clothes),
        Geom(f"{name}/head", "sphere", (s.head_radius,),
             (0.0, 0.0, s.height - s.head_radius), "skin"),
        Geom(f"{name}/arm_l", "capsule", (0.04, arm_half),
             (0.0, s.shoulder + 0.03, torso - 0.05), s.clothes),
        Geom(f"{name}/arm_r", "capsule", (0.04, arm_half),
             (0.0, -s.shoulder - 0.03, torso - 0.05), s.clothes),
    )
    bodies = [Body(name, "person", (x, y, 0.0), heading, upper, mocap=True, person_id=person_id)]
    half = (s.hip - s.leg_radius) / 2  # the capsule's foot touches the floor when upright
    for side, sign in (("l", 1.0), ("r", -1.0)):
        leg = Geom(f"{name}/leg_{side}", "capsule", (s.leg_radius, half), (0.0, 0.0, -half),
                   "trousers")
        hx = x - sign * HIP_HALF_WIDTH * np.sin(heading)
        hy = y + sign * HIP_HALF_WIDTH * np.cos(heading)
        bodies.append(Body(f"{name}/leg_{side}", "person_leg", (float(hx), float(hy), s.hip),
                           heading, (leg,), mocap=True, person_id=person_id))
    return bodies


def leg_swing(distance: ArrayLike, speed: ArrayLike, kinds: ArrayLike) -> NDArray[np.float64]:
    """Left-leg swing angle (rad, forward positive); the right leg swings by its negative.

    The gait phase advances one cycle per stride (two steps, 0.8 × the stature), so the feet
    keep pace with the ground; the amplitude grows with speed and is zero at rest.

    Args:
        distance: ``(n,)`` m walked since the start.
        speed: ``(n,)`` m/s, current walking speed.
        kinds: ``(n,)`` agent type codes.
    """
    d = np.asarray(distance, dtype=np.float64)
    v = np.abs(np.asarray(speed, dtype=np.float64))
    height = statures(kinds)
    phase = 2.0 * np.pi * d / (0.8 * height)
    return np.minimum(SWING_PER_SPEED * v, MAX_SWING) * np.sin(phase)


def _quat(yaw: NDArray[np.float64], pitch: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(n, 4)`` quaternions (w, x, y, z) of a yaw about z followed by a pitch about body y."""
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    return np.stack([cy * cp, -sy * sp, cy * sp, sy * cp], axis=-1)


def pose_figures(positions: ArrayLike, headings: ArrayLike, distance: ArrayLike,
                 speed: ArrayLike, kinds: ArrayLike) -> tuple[NDArray[np.float64],
                                                              NDArray[np.float64]]:
    """Mocap poses of ``n`` figures for the order of :func:`figure_bodies` (torso, left, right).

    Args:
        positions: ``(n, 2)`` m.
        headings: ``(n,)`` rad.
        distance: ``(n,)`` m walked since the start (the gait phase).
        speed: ``(n,)`` m/s (the swing amplitude).
        kinds: ``(n,)`` agent type codes.

    Returns:
        ``pos (n, 3, 3)`` m and ``quat (n, 3, 4)`` (w, x, y, z) for torso, left leg, right leg.
    """
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    yaw = np.asarray(headings, dtype=np.float64).reshape(-1)
    kinds = np.asarray(kinds).reshape(-1)
    n = p.shape[0]
    hip = HIP_FRACTION * statures(kinds)
    swing = leg_swing(distance, speed, kinds)
    pos = np.zeros((n, 3, 3))
    pos[:, 0, :2] = p
    lateral = np.stack([-np.sin(yaw), np.cos(yaw)], axis=-1) * HIP_HALF_WIDTH
    pos[:, 1, :2] = p + lateral
    pos[:, 2, :2] = p - lateral
    pos[:, 1:, 2] = hip[:, None]
    # a leg swinging forward turns its foot ahead: a negative pitch about the body's y axis
    quat = np.stack([_quat(yaw, np.zeros(n)), _quat(yaw, -swing), _quat(yaw, swing)], axis=1)
    return pos, quat

"""What the sensors see besides the static world: :class:`DynamicScene`, built each step.

Per world, in this order: the pedestrians' body circles (or two leg circles each with
``pedestrian_body: legs``; none when ``pedestrians_block_lidar`` is false), then, in worlds with
more than one robot, the robots in row order: a circular robot as a circle, a polygon robot as
its placed footprint edges, each owned by its robot row (its own lidar ignores it). A world with
one robot leaves its robot out: no other sensor could see it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.scene.state import AgentStates
from arena.sim.engine.params import EngineParams

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

_EMPTY_XY = np.zeros((0, 2))
_EMPTY_R = np.zeros(0)
_EMPTY_I = np.zeros(0, dtype=np.int64)


@dataclass(slots=True, eq=False)  # not frozen: built every step, and a frozen init costs 1 µs
class DynamicScene:
    """Circles and segments of every world; world ``w`` owns ``off[w]:off[w + 1]`` of each.

    Read-only by convention: nothing writes into a scene after :meth:`SceneBuilder.build`.

    Attributes:
        circ_off: ``(W + 1,)`` int64 circle offsets per world.
        circ_xy: ``(C, 2)`` circle centres (m).
        circ_r: ``(C,)`` circle radii (m).
        circ_owner: ``(C,)`` int64 global robot row owning the circle, ``-1`` nobody.
        seg_off: ``(W + 1,)`` int64 segment offsets per world.
        seg_a: ``(K, 2)`` segment start points (m).
        seg_b: ``(K, 2)`` segment end points (m).
        seg_owner: ``(K,)`` int64 global robot row owning the segment, ``-1`` nobody.
    """

    circ_off: I64
    circ_xy: F64
    circ_r: F64
    circ_owner: I64
    seg_off: I64
    seg_a: F64
    seg_b: F64
    seg_owner: I64


def pedestrian_circles(
    agents: AgentStates, walked: F64, params: EngineParams
) -> tuple[F64, F64]:
    """``(centres (m, 2), radii (m,))`` the lidar sees of the pedestrians of one world.

    ``walked``: ``(n,)`` m each pedestrian walked since the reset (the legs' gait phase).
    """
    if not params.pedestrians_block_lidar:
        return _EMPTY_XY, _EMPTY_R
    if params.pedestrian_body == "legs":
        return legs(agents, walked, params)
    return agents.positions, agents.radii


def legs(agents: AgentStates, walked: F64, params: EngineParams) -> tuple[F64, F64]:
    """Two leg circles per pedestrian, swinging with a gait phase from the distance walked.

    Legs sit ``hip_half_width`` either side of the heading axis and swing in antiphase by
    ``stride_amplitude · min(1, speed / 1 m/s) · sin(phase)``; ``phase`` advances 2π per
    ``stride_length`` walked, so a lidar sees the scissor motion trackers rely on. Returns
    ``(centres (2n, 2) m, radii (2n,) m)``, all left legs first.
    """
    p = params
    n = len(agents)
    if walked.shape[0] != n:
        walked = np.zeros(n)
    phase = 2.0 * np.pi * walked / p.stride_length
    speed = np.hypot(agents.velocities[:, 0], agents.velocities[:, 1])
    swing = p.stride_amplitude * np.minimum(1.0, speed) * np.sin(phase)
    h = agents.headings
    fwd = np.stack([np.cos(h), np.sin(h)], axis=1)
    lat = np.stack([-np.sin(h), np.cos(h)], axis=1)
    left = agents.positions + p.hip_half_width * lat + swing[:, None] * fwd
    right = agents.positions - p.hip_half_width * lat - swing[:, None] * fwd
    return np.concatenate([left, right]), np.full(2 * n, p.leg_radius)


class SceneBuilder:
    """Builds the :class:`DynamicScene` of a step; keeps the constant arrays between steps."""

    def __init__(self) -> None:
        self._owners: dict[int, I64] = {}  # ``-1`` arrays by length (never written)
        self._off1 = np.zeros(2, dtype=np.int64)  # ``[0, m]``: one world's offsets (never written)

    def _nobody(self, n: int) -> I64:
        a = self._owners.get(n)
        if a is None:
            # writeable: numba compiles another specialisation for read-only arrays
            a = np.full(n, -1, dtype=np.int64)
            if len(self._owners) > 64:
                self._owners.clear()
            self._owners[n] = a
        return a

    def build(
        self,
        peds: Sequence[tuple[F64, F64]],
        robot_off: I64,
        poses: F64,
        radii: F64,
        polygons: Sequence[F64 | None],
    ) -> DynamicScene:
        """The scene of all worlds.

        Args:
            peds: per world, ``(centres (m, 2), radii (m,))`` from :func:`pedestrian_circles`.
            robot_off: ``(W + 1,)`` robot row offsets per world.
            poses: ``(R, 3)`` robot poses.
            radii: ``(R,)`` robot footprint radii (m), for circular robots.
            polygons: per robot row, its ``(k, 2)`` placed footprint polygon (world frame) or
                ``None`` for a circular robot; only read in worlds with several robots.
        """
        w_n = len(peds)
        if w_n == 1 and robot_off[1] - robot_off[0] <= 1:  # the common single-robot world
            cxy, cr = peds[0]
            m = cr.shape[0]
            if self._off1[1] != m:
                self._off1 = np.array([0, m], dtype=np.int64)
            return DynamicScene(
                self._off1, cxy, cr, self._nobody(m),
                _ZERO_OFF_1, _EMPTY_XY, _EMPTY_XY, _EMPTY_I,
            )
        c_xy: list[F64] = []
        c_r: list[F64] = []
        c_own: list[I64] = []
        s_a: list[F64] = []
        s_b: list[F64] = []
        s_own: list[I64] = []
        circ_off = np.zeros(w_n + 1, dtype=np.int64)
        seg_off = np.zeros(w_n + 1, dtype=np.int64)
        nc = ns = 0
        for w in range(w_n):
            cxy, cr = peds[w]
            c_xy.append(cxy)
            c_r.append(cr)
            c_own.append(self._nobody(cr.shape[0]))
            nc += cr.shape[0]
            r0, r1 = int(robot_off[w]), int(robot_off[w + 1])
            if r1 - r0 > 1:
                for j in range(r0, r1):
                    poly = polygons[j]
                    if poly is None:
                        c_xy.append(poses[j : j + 1, :2])
                        c_r.append(np.array([radii[j]]))
                        c_own.append(np.array([j], dtype=np.int64))
                        nc += 1
                    else:
                        s_a.append(poly)
                        s_b.append(np.roll(poly, -1, axis=0))
                        s_own.append(np.full(len(poly), j, dtype=np.int64))
                        ns += len(poly)
            circ_off[w + 1] = nc
            seg_off[w + 1] = ns
        return DynamicScene(
            circ_off,
            np.concatenate(c_xy) if c_xy else _EMPTY_XY,
            np.concatenate(c_r) if c_r else _EMPTY_R,
            np.concatenate(c_own) if c_own else _EMPTY_I,
            seg_off,
            np.concatenate(s_a) if s_a else _EMPTY_XY,
            np.concatenate(s_b) if s_b else _EMPTY_XY,
            np.concatenate(s_own) if s_own else _EMPTY_I,
        )


_ZERO_OFF_1 = np.zeros(2, dtype=np.int64)

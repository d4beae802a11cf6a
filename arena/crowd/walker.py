"""The simplest crowd model: pedestrians walk their waypoints and ignore everyone.

It is the baseline every social model is compared with, and the default until the crowd
issue's models land. Motion: the velocity turns toward the current waypoint at the agent's
preferred speed, limited by a maximum acceleration, so paths are smooth and speeds bounded.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.base import CROWD_MODELS
from arena.sim.state import AgentStates, RobotStates, StaticWorld
from arena.tasks.episode import WAYPOINT_RANDOM, AgentSpawn


@CROWD_MODELS.register("waypoint_walker", tags=("baseline",))
class WaypointWalker:
    """Pedestrians walk straight to their waypoints at their preferred speed, without avoidance."""

    class Params(BaseModel):
        """Parameters of :class:`WaypointWalker`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        max_acceleration: float = Field(1.5, gt=0, description="m/s², limit on velocity change")
        arrival_radius: float = Field(0.3, gt=0, description="m, a waypoint counts as reached")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self._spawn: AgentSpawn | None = None

    def reset(self, spawn: AgentSpawn, world: StaticWorld, rng: np.random.Generator) -> AgentStates:
        """Put the agents at their start positions, at rest, heading to their first waypoint."""
        self._spawn = spawn
        self._rng = rng
        n = len(spawn)
        self._pos = spawn.positions.astype(np.float64, copy=True)
        self._vel = np.zeros((n, 2))
        self._idx = np.zeros(n, dtype=np.int64)
        self._rows = np.arange(n)
        self._random = (spawn.waypoint_mode == WAYPOINT_RANDOM) & (spawn.num_waypoints > 1)
        self._no_shifts = np.zeros(n, dtype=np.int64)
        d = spawn.waypoints[self._rows, self._idx] - self._pos
        self._heading = np.arctan2(d[:, 1], d[:, 0]) if n else np.zeros(0)
        return self._snapshot()

    def step(self, robots: RobotStates, dt: float) -> AgentStates:
        """Advance every agent by ``dt`` seconds (robots are ignored by this model)."""
        sp = self._spawn
        if sp is None:
            raise RuntimeError("WaypointWalker.step called before reset")
        if len(sp) == 0:
            return self._snapshot()
        # Agents in random mode that arrive now draw their shift to another waypoint here, from
        # the episode's generator; the compiled kernel then only does arithmetic.
        shifts = self._no_shifts
        if self._random.any():
            to_target = sp.waypoints[self._rows, self._idx] - self._pos
            arrived = np.einsum("ij,ij->i", to_target, to_target) < self.params.arrival_radius**2
            arriving = arrived & self._random
            if arriving.any():
                shifts = np.zeros(len(sp), dtype=np.int64)
                shifts[arriving] = self._rng.integers(1, sp.num_waypoints[arriving])
        _walk_kernel(
            self._pos,
            self._vel,
            self._heading,
            self._idx,
            sp.waypoints,
            sp.num_waypoints,
            sp.vmax,
            shifts,
            self.params.arrival_radius,
            self.params.max_acceleration,
            dt,
        )
        return self._snapshot()

    def _snapshot(self) -> AgentStates:
        sp = self._spawn
        assert sp is not None
        n = len(sp)
        return AgentStates(
            ids=np.arange(n, dtype=np.int64),
            positions=self._pos.copy(),
            velocities=self._vel.copy(),
            headings=self._heading.copy(),
            radii=sp.radii.astype(np.float64, copy=True),
            kinds=sp.kinds.astype(np.int64, copy=True),
            states=np.zeros(n, dtype=np.int64),
        )


@njit(cache=True)
def _walk_kernel(
    pos: np.ndarray,
    vel: np.ndarray,
    heading: np.ndarray,
    idx: np.ndarray,
    waypoints: np.ndarray,
    num_waypoints: np.ndarray,
    vmax: np.ndarray,
    shifts: np.ndarray,
    arrival_radius: float,
    max_acc: float,
    dt: float,
) -> None:
    """Advance every agent in place (compiled: one call per step instead of ~30 numpy ops)."""
    r2 = arrival_radius * arrival_radius
    max_dv = max_acc * dt
    for i in range(pos.shape[0]):
        k = idx[i]
        dx = waypoints[i, k, 0] - pos[i, 0]
        dy = waypoints[i, k, 1] - pos[i, 1]
        if dx * dx + dy * dy < r2:
            # Loop: next waypoint; random: the pre-drawn shift to another waypoint.
            step = shifts[i] if shifts[i] > 0 else 1
            k = (k + step) % num_waypoints[i]
            idx[i] = k
            dx = waypoints[i, k, 0] - pos[i, 0]
            dy = waypoints[i, k, 1] - pos[i, 1]
        dist = math.sqrt(dx * dx + dy * dy)
        # Slow down on the last stretch so the agent does not orbit its waypoint.
        speed = min(vmax[i], dist / max(dt, 1e-9))
        if dist > 1e-9:
            ux, uy = dx / dist * speed, dy / dist * speed
        else:
            ux, uy = 0.0, 0.0
        dvx, dvy = ux - vel[i, 0], uy - vel[i, 1]
        dvn = math.sqrt(dvx * dvx + dvy * dvy)
        scale = min(1.0, max_dv / max(dvn, 1e-12))
        vel[i, 0] += dvx * scale
        vel[i, 1] += dvy * scale
        pos[i, 0] += vel[i, 0] * dt
        pos[i, 1] += vel[i, 1] * dt
        if vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1] > 1e-6:
            heading[i] = math.atan2(vel[i, 1], vel[i, 0])

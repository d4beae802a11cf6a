"""ORCA local planner: the robot as an ORCA agent among static laser obstacles.

Description:
    Optimal reciprocal collision avoidance (van den Berg, Guy, Snape, Lin & Manocha 2011),
    computed in the robot frame each tick:

    - preferred velocity: toward a lookahead point ``lookahead`` m ahead on the global path at
      the cruise speed, capped by the braking speed to the goal;
    - neighbours: the laser returns are reduced to the ``obstacles`` nearest clustered returns
      (:func:`~arena.nav.local_planners.path_tracking.cluster_points`), each a motionless
      neighbour of radius ``obstacle_radius`` that does not react (the robot takes full
      responsibility); each gives one ORCA half-plane for the time horizon ``time_horizon`` (s)
      over the combined radius ``robot_radius + margin + obstacle_radius``;
    - new velocity: the point closest to the preferred velocity inside the max-speed disc and
      every half-plane, by RVO2's incremental 2-D linear program; if that is infeasible, the
      3-D fallback minimises the largest violation. The half-plane construction and both linear
      programs are those of :mod:`arena.crowd.models.orca` (our re-implementation of RVO2).

    The holonomic velocity is capped, along its direction, at the braking speed to the nearest
    laser return in the way, then turned into a twist for the kinematics by
    :func:`~arena.nav.local_planners.social_force.velocity_to_twist` (omni: as is; diff-drive
    and legged: heading control; car-like: curvature-bounded steering).

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Arguments:
    See :class:`OrcaPlanner.Params`.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field

from arena.crowd.models.orca.kernels import RVO_EPSILON, _agent_line, _lp2, _lp3
from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    stopping_speed,
)
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    TrackingParams,
    at_goal,
    cluster_points,
    goal_command,
)
from arena.nav.local_planners.social_force import (
    cap_by_returns,
    lookahead_target,
    velocity_to_twist,
)

_C = (0.0, 0.5, 1.0, RVO_EPSILON, float("inf"))  # zero, ½, 1, ε, inf (the kernels' constants)


def orca_velocity(
    velocity: NDArray[np.float64],
    preferred: NDArray[np.float64],
    neighbours: NDArray[np.float64],
    combined_radius: float,
    max_speed: float,
    time_horizon: float,
    dt: float,
) -> NDArray[np.float64]:
    """ORCA velocity ``(2,)`` (m/s) of an agent at the origin among motionless neighbours.

    Args:
        velocity: ``(2,)`` current velocity (m/s).
        preferred: ``(2,)`` preferred velocity (m/s).
        neighbours: ``(k, 2)`` neighbour positions (m) relative to the agent.
        combined_radius: agent radius + neighbour radius (m).
        max_speed: radius of the velocity disc (m/s).
        time_horizon: s, horizon of the velocity obstacles.
        dt: s, time step used when already overlapping (RVO2's ``1 / timeStep`` cut-off).

    Returns:
        The new velocity; full responsibility is taken for every (non-reacting) neighbour.
    """
    k = len(neighbours)
    vx, vy = float(velocity[0]), float(velocity[1])
    lines = np.empty((max(k, 1), 4), dtype=np.float64)
    for i in range(k):
        rpx, rpy = float(neighbours[i, 0]), float(neighbours[i, 1])
        lines[i] = _agent_line(rpx, rpy, vx, vy, vx, vy, combined_radius, 1.0 / time_horizon,
                               1.0 / dt, 1.0, 1.0, _C)
    fail, rx, ry = _lp2(lines, k, max_speed, float(preferred[0]), float(preferred[1]), False, _C)
    if fail < k:
        rx, ry = _lp3(lines, k, 0, fail, max_speed, rx, ry, np.empty_like(lines), _C)
    out = np.array([rx, ry], dtype=np.float64)
    return out if np.all(np.isfinite(out)) else np.zeros(2)


@LOCAL_PLANNERS.register("orca", tags=("reactive", "velocity-obstacle"))
class OrcaPlanner:
    """ORCA local planner (van den Berg et al. 2011); see the module docstring.

    Args:
        params: validated :class:`OrcaPlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(TrackingParams):
        """Parameters of :class:`OrcaPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        lookahead: float = Field(1.0, gt=0, description="m, preferred-velocity target on the path")
        time_horizon: float = Field(1.5, gt=0, description="s, horizon of the velocity obstacles")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        obstacles: int = Field(16, ge=0, description="clustered laser returns avoided")
        cluster_radius: float = Field(
            0.15, gt=0, description="m, laser returns within this of a kept one are merged"
        )
        obstacle_radius: float = Field(
            0.05, ge=0, description="m, radius given to each clustered return"
        )
        margin: float = Field(0.05, ge=0, description="m, clearance added to the robot radius")
        reach: float = Field(3.0, gt=0, description="m, returns beyond this are ignored")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._tracker = PathTracker()
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path and the progress along it."""
        self._tracker.reset()

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self.params
        lim = obs.limits
        target, d_goal, d_end = lookahead_target(self._tracker, obs, p.lookahead)
        if at_goal(obs, d_end, p.goal_tolerance):
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)
        decel = p.decel_fraction * lim.acc_x
        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        v_pref = min(v_top, stopping_speed(d_goal, decel))
        dist = float(np.hypot(target[0], target[1]))
        pref = target * (v_pref / dist) if dist > 1e-9 else np.zeros(2)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        vel = twist[:2].copy() if lim.holonomic else np.array([twist[0], 0.0])
        pts = obs.scan_points()
        cl = (cluster_points(pts, p.obstacles, p.cluster_radius, p.reach)
              if p.obstacles > 0 and len(pts) else np.zeros((0, 2)))
        radius = obs.robot_radius + p.margin + p.obstacle_radius
        new = orca_velocity(vel, pref, cl, radius, max(v_top, 1e-6), p.time_horizon,
                            max(float(obs.dt), 1e-3))
        new = cap_by_returns(new, obs, p.stop_distance, decel)
        return velocity_to_twist(new, obs, p.heading_gain, p.rotate_threshold, p.lookahead)

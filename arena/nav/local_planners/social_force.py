"""Social force local planner: the robot as a Helbing social-force agent.

Description:
    The robot is treated as a pedestrian of the social force model (Helbing & Molnár 1995),
    computed in the robot frame each tick:

    - attraction ``(v_pref · e - v) / tau`` toward a lookahead point on the global path
      (``lookahead`` m ahead of the robot's projection), with ``v_pref`` the cruise speed capped
      by the braking speed to the goal, ``e`` the unit direction to the lookahead point, ``v``
      the current planar velocity and ``tau`` (s) the relaxation time;
    - repulsion from obstacles: the laser returns are reduced to the ``obstacles`` nearest
      clustered returns, each pushing with ``A · exp((r - d) / B)`` (m/s²) along the direction
      from the return to the robot, ``d`` the distance (m), ``r`` the robot radius, plus
      ``side_weight ×`` that magnitude × ``cos`` (angle of the return off the direction of
      travel, if ahead) perpendicular to the direction of travel, away from the return's
      side (a return dead on the path would otherwise be a dead end of the pure model);
    - optional repulsion from pedestrians (``pedestrians`` argument of :meth:`compute`, world
      positions, same law with the combined radius).

    The force is integrated over the control period into a desired planar velocity (over
    ``tau`` for non-holonomic robots, which steer toward the relaxed velocity), capped at
    the cruise speed and, along its direction, at the braking speed to the nearest laser return
    in the way (:func:`~arena.nav.local_planners.path_tracking.free_distance`). The velocity is
    then turned into a twist for the kinematics (:func:`velocity_to_twist`): omni robots move
    along it and turn toward it; diff-drive and legged robots steer toward it (heading control:
    the speed is scaled by the cosine of the heading error, turning on the spot beyond
    ``rotate_threshold``); car-like robots steer with the curvature bound.

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Arguments:
    See :class:`SocialForcePlanner.Params`.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field

from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    limit_command,
    stopping_speed,
)
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    TrackingParams,
    at_goal,
    cluster_points,
    finish_command,
    free_distance,
    goal_command,
    to_robot_frame,
)


def velocity_to_twist(
    vel: NDArray[np.float64], obs: LocalObservation, heading_gain: float, rotate_threshold: float,
    steer_distance: float = 1.0,
) -> NDArray[np.float64]:
    """A feasible body twist ``(3,)`` realising the desired planar velocity ``vel`` (robot frame).

    Args:
        vel: ``(2,)`` desired velocity (m/s) in the robot frame.
        obs: the observation (limits, twist, kinematics, control period).
        heading_gain: 1/s, yaw rate per radian of heading error.
        rotate_threshold: rad, heading error beyond which diff-drive robots turn on the spot.
        steer_distance: m, car-like robots steer on the arc through the point this far along
            ``vel`` (pure-pursuit curvature ``2 sin(alpha) / steer_distance``).

    Returns:
        ``(3,)`` ``[vx, vy, omega]`` within the acceleration window and the velocity box.
    """
    lim = obs.limits
    dt = float(obs.dt)
    twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
    drive = obs.drive
    car = drive == "ackermann" or lim.min_turning_radius > 0
    speed = float(math.hypot(vel[0], vel[1]))
    alpha = math.atan2(vel[1], vel[0]) if speed > 1e-9 else 0.0
    if drive == "omni" and lim.holonomic and not car:
        # Scale the whole velocity into the box so the direction is kept.
        scale = 1.0
        for comp, lo, hi in ((vel[0], lim.vx_min, lim.vx_max), (vel[1], lim.vy_min, lim.vy_max)):
            if comp > hi > 0 or (comp > 0 and hi <= 0):
                scale = min(scale, max(hi, 0.0) / comp)
            elif comp < lo < 0 or (comp < 0 and lo >= 0):
                scale = min(scale, max(-lo, 0.0) / -comp)
        want = vel * scale
        dv = want - twist[:2]
        room = np.array([lim.acc_x, lim.acc_y]) * dt
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.where(np.abs(dv) > 1e-12, room / np.abs(dv), np.inf)
        vxy = twist[:2] + min(1.0, float(np.min(ratios))) * dv
        cmd = np.array([vxy[0], vxy[1], heading_gain * alpha if speed > 1e-3 else 0.0])
        return finish_command(cmd, twist, lim, dt, False)
    if car:
        # Steer toward the velocity: curvature of the arc through a point along it.
        v = speed * max(math.cos(alpha), 0.0)
        if speed > 1e-9 and abs(alpha) > math.pi / 2:
            v = min(speed, 0.3 * lim.vx_max)  # behind: drive the tightest turn slowly
        v = float(np.clip(v, max(lim.vx_min, 0.0), lim.vx_max))
        kappa = 2.0 * math.sin(alpha) / steer_distance
        r = lim.min_turning_radius
        if r > 0:
            kappa = float(np.clip(kappa, -1.0 / r, 1.0 / r))
        cmd = np.array([v, 0.0, kappa * v])
        out = limit_command(cmd, twist, lim, dt)
        out[2] = kappa * out[0]
        return finish_command(out, out, lim, dt, True)
    # Diff-drive / legged: heading control.
    w = heading_gain * alpha
    v = 0.0 if abs(alpha) > rotate_threshold else speed * math.cos(alpha)
    v = max(v, 0.0)
    return finish_command(np.array([v, 0.0, w]), twist, lim, dt, False)


def lookahead_target(
    tracker: PathTracker, obs: LocalObservation, lookahead: float
) -> tuple[NDArray[np.float64], float, float]:
    """Lookahead point in the robot frame, distance left to the goal and to the path end (m)."""
    pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
    path = PathTracker.normalise(obs.path, obs.goal_pose.xy)
    goal_xy = obs.goal_pose.xy
    if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
        path = np.vstack([path, goal_xy])
    s = tracker.track(path, pose[:2])
    d_end = float(np.hypot(*(path[-1] - pose[:2])))
    target = to_robot_frame(tracker.point_at(s + lookahead), pose)
    return target, max(tracker.total - s, d_end), d_end


@LOCAL_PLANNERS.register("social_force", tags=("reactive", "social"))
class SocialForcePlanner:
    """Social-force local planner (Helbing); see the module docstring.

    Args:
        params: validated :class:`SocialForcePlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(TrackingParams):
        """Parameters of :class:`SocialForcePlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        lookahead: float = Field(1.0, gt=0, description="m, attraction point ahead on the path")
        tau: float = Field(0.5, gt=0, description="s, relaxation time of the attraction")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        obstacle_a: float = Field(2.0, ge=0, description="m/s², obstacle repulsion strength A")
        obstacle_b: float = Field(0.3, gt=0, description="m, obstacle repulsion range B")
        side_weight: float = Field(
            1.0, ge=0, description="share of the repulsion of returns ahead applied sideways"
        )
        pedestrian_a: float = Field(3.0, ge=0, description="m/s², pedestrian repulsion A")
        pedestrian_b: float = Field(0.4, gt=0, description="m, pedestrian repulsion range B")
        pedestrian_radius: float = Field(0.3, ge=0, description="m, radius of a pedestrian")
        obstacles: int = Field(12, ge=0, description="clustered laser returns that repel")
        cluster_radius: float = Field(
            0.2, gt=0, description="m, laser returns within this of a kept one are merged"
        )
        reach: float = Field(2.0, gt=0, description="m, returns beyond this do not repel")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._tracker = PathTracker()
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path and the progress along it."""
        self._tracker.reset()

    def force(
        self, obs: LocalObservation, target: NDArray[np.float64], v_pref: float,
        pedestrians: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Total social force ``(2,)`` (m/s², robot frame) for a lookahead ``target`` (robot frame).

        Args:
            obs: the observation.
            target: ``(2,)`` attraction point (m, robot frame).
            v_pref: preferred speed (m/s).
            pedestrians: ``(q, 2)`` pedestrian positions (m, world frame), or ``None``.
        """
        p = self.params
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        dist = float(np.hypot(target[0], target[1]))
        e = target / dist if dist > 1e-9 else np.zeros(2)
        f = (v_pref * e - twist[:2]) / p.tau
        pts = obs.scan_points()
        if p.obstacles > 0 and len(pts):
            cl = cluster_points(pts, p.obstacles, p.cluster_radius, p.reach)
            if len(cl):
                d = np.maximum(np.hypot(cl[:, 0], cl[:, 1]), 1e-6)
                mag = p.obstacle_a * np.exp((obs.robot_radius - d) / p.obstacle_b)
                f = f - (mag / d) @ cl
                if p.side_weight > 0 and dist > 1e-9:
                    # Sidestep: returns ahead push sideways, away from the side they lie on
                    # (right when dead ahead), so a return on the path is not a dead end.
                    ahead = np.maximum((cl @ e) / d, 0.0)
                    side = np.where(e[0] * cl[:, 1] - e[1] * cl[:, 0] > 0.0, -1.0, 1.0)
                    perp = np.array([-e[1], e[0]])
                    f = f + p.side_weight * float(np.sum(mag * ahead * side)) * perp
        if pedestrians is not None and len(pedestrians):
            rel = to_robot_frame(np.asarray(pedestrians, dtype=np.float64).reshape(-1, 2),
                                 np.asarray(obs.pose, dtype=np.float64).reshape(3))
            d = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-6)
            r = obs.robot_radius + p.pedestrian_radius
            mag = p.pedestrian_a * np.exp((r - d) / p.pedestrian_b)
            f = f - (mag / d) @ rel
        return np.asarray(f, dtype=np.float64)

    def compute(
        self, obs: LocalObservation, pedestrians: NDArray[np.float64] | None = None
    ) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring.

        Args:
            obs: the observation.
            pedestrians: optional ``(q, 2)`` pedestrian positions (m, world frame) to avoid;
                by default those the stack put in ``obs.pedestrians``.
        """
        p = self.params
        lim = obs.limits
        target, d_goal, d_end = lookahead_target(self._tracker, obs, p.lookahead)
        if at_goal(obs, d_end, p.goal_tolerance):
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)
        decel = p.decel_fraction * lim.acc_x
        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        v_pref = min(v_top, stopping_speed(d_goal, decel))
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        if pedestrians is None and len(obs.pedestrians):
            pedestrians = np.asarray(obs.pedestrians, dtype=np.float64)[:, :2]  # from the stack
        f = self.force(obs, target, v_pref, pedestrians)
        vel = twist[:2] + f * float(obs.dt)
        if not lim.holonomic:
            # A non-holonomic robot cannot follow the force sideways within one tick; it steers
            # toward the relaxed velocity v + tau · F = v_pref · e + tau · F_repulsion instead
            # (its speed is then ramped by the acceleration limits).
            vel = np.array([twist[0], 0.0]) + f * p.tau
        speed = float(np.hypot(vel[0], vel[1]))
        if speed > v_pref and speed > 1e-9:
            vel = vel * (v_pref / speed)
        vel = _cap_by_returns(vel, obs, p.stop_distance, decel)
        return velocity_to_twist(vel, obs, p.heading_gain, p.rotate_threshold, p.lookahead)


def _cap_by_returns(
    vel: NDArray[np.float64], obs: LocalObservation, stop_distance: float, decel: float
) -> NDArray[np.float64]:
    """``vel`` (robot frame) capped at the braking speed to the nearest return along it."""
    speed = float(np.hypot(vel[0], vel[1]))
    pts = obs.scan_points()
    if speed < 1e-9 or len(pts) == 0:
        return vel
    gap = free_distance(pts, vel / speed, obs.robot_radius)
    v_max = stopping_speed(gap - stop_distance, decel)
    if speed > v_max:
        # Keep a tiny velocity along the direction so the heading controller still steers.
        return vel * (max(v_max, 1e-6) / speed)
    return vel


cap_by_returns = _cap_by_returns
"""Public alias: cap a planar velocity by the braking speed to the nearest return along it."""

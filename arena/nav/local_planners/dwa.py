"""Dynamic Window Approach (Fox, Burgard & Thrun 1997; as in ROS ``dwa_local_planner``).

Description:
    Each tick the planner samples velocities from the *dynamic window*: the velocities reachable
    from the current twist within one control period (``|v - v0| ≤ acc · dt``), intersected with
    the velocity box. ``vx`` and ``omega`` are sampled on a grid (plus ``vy`` for ``omni``
    robots). Car-like robots (``ackermann``) sample the curvature ``κ ∈ [-1/R_min, 1/R_min]``
    instead of ``omega`` and command ``omega = κ · vx``, so the turning radius holds exactly.
    Backward samples (``vx < 0``) are only drawn with ``allow_reverse`` (or when the window
    holds no ``vx ≥ 0``): most lasers do not see behind the robot.

    Every sample is held constant for ``sim_time`` seconds and rolled out with the robot's exact
    SE(2) kinematics (arcs; see :func:`arena.robots.kinematics.integrate_twist`) at ``steps``
    points in time. Laser returns near the robot are reduced to a ``voxel`` grid, and a compiled
    kernel computes, for all samples × time steps × points at once, the clearance of the robot
    disc (``robot_radius``) and the first time it would touch a return it is approaching.

    Admissibility (Fox et al.): a sample is kept if it never touches a return within
    ``sim_time``, or if the robot can still brake to a stop before contact, i.e. its speed is at
    most ``sqrt(2 · decel · (d_free - stop_distance))`` with ``d_free`` the distance travelled
    before contact, and if its clearance stays ``≥ min_clearance`` (or, when the robot is
    already closer, does not shrink). Turning on the spot (speed 0) is always admissible. The
    speed is also capped by the braking speed to the goal. If nothing is admissible the robot
    brakes as hard as allowed.

    Scoring (lower is better), all distances in metres:

    - ``path_weight ×`` mean distance of the rollout to the global path,
    - ``goal_weight ×`` path length left from the trajectory end's projection to the local goal
      (the path point ``local_goal_distance`` ahead of the robot's projection); when the local
      goal is the path end, the closest approach to it along the trajectory counts instead, so
      slowing down to stop on it is not penalised,
    - ``heading_weight ×`` ``|angle from the end heading to the local goal| / π``,
    - ``obstacle_weight × exp(-clearance / obstacle_scale)``, faded out linearly over the last
      ``goal_fade`` metres before the goal,
    - ``speed_weight × (v_ref - v) / v_ref`` (forward speed, or the speed for omni robots).

    Ties go to the first sample in a fixed order, so the planner is deterministic.

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Arguments:
    See :class:`DWAPlanner.Params`.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    limit_command,
    stopping_speed,
)
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    at_goal,
    finish_command,
    goal_command,
    to_robot_frame,
)
from arena.robots.limits import VelocityLimits


@njit(cache=True)
def _clearance_kernel(
    xs: NDArray[np.float64],
    ys: NDArray[np.float64],
    pts: NDArray[np.float64],
    radius: float,
    clear: NDArray[np.float64],
    first: NDArray[np.int64],
) -> None:
    """Per-sample clearance (m) and first contact step of rollouts against laser points.

    For each sample ``i``: min clearance over its ``(T,)`` positions ``xs[i], ys[i]`` to ``pts``
    ``(m, 2)``, and the first step index touching a return it approaches (``T`` if none).
    """
    n, t_count = xs.shape
    m = pts.shape[0]
    d0 = np.empty(m)
    for j in range(m):
        d0[j] = math.hypot(pts[j, 0], pts[j, 1])
    r2 = radius * radius
    for i in range(n):
        best = np.inf
        hit = t_count
        for k in range(t_count):
            x, y = xs[i, k], ys[i, k]
            for j in range(m):
                dx = pts[j, 0] - x
                dy = pts[j, 1] - y
                q = dx * dx + dy * dy
                if q < best:
                    best = q
                if hit == t_count and q < r2 and q < d0[j] * d0[j] - 1e-12:
                    hit = k
        clear[i] = math.sqrt(best) - radius if m > 0 else np.inf
        first[i] = hit


def rollout(
    samples: NDArray[np.float64], times: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Body-frame poses of constant twists: ``samples`` ``(n, 3)``, ``times`` ``(T,)`` (s).

    Returns:
        ``(x, y, theta)``, each ``(n, T)`` (m, m, rad), starting from the origin facing +x.
    """
    vx, vy, w = samples[:, 0:1], samples[:, 1:2], samples[:, 2:3]
    t = times[None, :]
    phi = w * t
    small = np.abs(w) < 1e-6
    w_safe = np.where(small, 1.0, w)
    s = np.where(small, t * (1.0 - phi * phi / 6.0), np.sin(phi) / w_safe)
    c = np.where(small, t * phi * (0.5 - phi * phi / 24.0), (1.0 - np.cos(phi)) / w_safe)
    return s * vx - c * vy, c * vx + s * vy, phi


def _axis(lo: float, hi: float, count: int, current: float) -> NDArray[np.float64]:
    """``count`` values spanning ``[lo, hi]`` plus ``current`` (if inside) and 0 (if inside)."""
    vals = np.linspace(lo, hi, max(count, 1)) if hi > lo else np.array([lo])
    extra = [v for v in (current, 0.0) if lo <= v <= hi]
    return np.unique(np.concatenate([vals, np.array(extra, dtype=np.float64)]))


def _window(twist: NDArray[np.float64], lim: VelocityLimits, dt: float) -> tuple[
    NDArray[np.float64], NDArray[np.float64]
]:
    """Lower and upper ``(3,)`` corners of the dynamic window (velocity box applied last)."""
    step = lim.acceleration * max(dt, 0.0)
    return lim.clip(twist - step), lim.clip(twist + step)


@LOCAL_PLANNERS.register("dwa", tags=("classic", "sampling"))
class DWAPlanner:
    """Dynamic Window Approach local planner (velocity sampling + forward simulation).

    Args:
        params: validated :class:`DWAPlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of :class:`DWAPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        sim_time: float = Field(1.5, gt=0, description="s, forward-simulation horizon")
        steps: int = Field(20, ge=2, le=200, description="time steps of each rollout")
        vx_samples: int = Field(11, ge=1, description="samples of vx in the window")
        vy_samples: int = Field(5, ge=1, description="samples of vy (omni robots only)")
        omega_samples: int = Field(
            21, ge=1, description="samples of omega (of the curvature for ackermann robots)"
        )
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        path_weight: float = Field(1.0, ge=0, description="1/m, weight of the path distance")
        goal_weight: float = Field(1.2, ge=0, description="1/m, weight of the goal distance")
        heading_weight: float = Field(0.3, ge=0, description="weight of the heading term")
        obstacle_weight: float = Field(0.6, ge=0, description="weight of the obstacle term")
        speed_weight: float = Field(0.1, ge=0, description="weight of the speed term")
        goal_fade: float = Field(
            1.0, ge=0, description="m before the goal over which the obstacle term fades out"
        )
        obstacle_scale: float = Field(
            0.25, gt=0, description="m, decay length of the obstacle cost with clearance"
        )
        local_goal_distance: float = Field(
            2.0, gt=0, description="m, local goal ahead of the robot along the path (at least "
            "the distance covered in sim_time at top speed)",
        )
        stop_distance: float = Field(
            0.1, ge=0, description="m, clearance kept when braking before a laser return"
        )
        min_clearance: float = Field(
            0.05, ge=0, description="m, smallest clearance to a return a moving rollout may have"
        )
        decel_fraction: float = Field(
            0.8, gt=0, le=1, description="share of the acceleration limit used for braking"
        )
        voxel: float = Field(
            0.05, gt=0, description="m, grid to which laser returns are reduced before checking"
        )
        goal_tolerance: float = Field(
            0.05, gt=0, description="m, distance to the path end at which the planner stops"
        )
        allow_reverse: bool = Field(
            False, description="sample vx < 0 (backwards, where lasers often cannot see); a "
            "robot already reversing may always keep doing so within its window",
        )
        heading_gain: float = Field(
            2.0, gt=0, description="1/s, proportional gain of in-place goal alignment"
        )
        goal_yaw_tolerance: float = Field(
            0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._tracker = PathTracker()
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path and the progress along it."""
        self._tracker.reset()

    # -- sampling -------------------------------------------------------------------------------
    def samples(self, obs: LocalObservation) -> NDArray[np.float64]:
        """``(n, 3)`` velocity samples of the dynamic window for ``obs`` (before any check)."""
        p = self.params
        lim = obs.limits
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        lo, hi = _window(twist, lim, float(obs.dt))
        cur = lim.clip(twist)
        if not p.allow_reverse:
            lo[0] = max(lo[0], min(0.0, hi[0]))
        vx = _axis(lo[0], hi[0], p.vx_samples, cur[0])
        drive = obs.drive
        if drive == "ackermann" or lim.min_turning_radius > 0:
            k_max = 1.0 / lim.min_turning_radius if lim.min_turning_radius > 0 else 0.0
            kappa = np.linspace(-k_max, k_max, p.omega_samples) if k_max > 0 else np.zeros(1)
            kappa = np.unique(np.concatenate([kappa, [0.0]]))
            v, k = np.meshgrid(vx, kappa, indexing="ij")
            v, k = v.ravel(), k.ravel()
            w = np.clip(k * v, -lim.omega_max, lim.omega_max)
            return np.stack([v, np.zeros_like(v), w], axis=-1)
        w_axis = _axis(lo[2], hi[2], p.omega_samples, cur[2])
        if drive == "omni" and lim.holonomic:
            vy = _axis(lo[1], hi[1], p.vy_samples, cur[1])
        else:
            vy = np.zeros(1)
        grid = np.meshgrid(vx, vy, w_axis, indexing="ij")
        return np.stack([g.ravel() for g in grid], axis=-1)

    # -- control ----------------------------------------------------------------------------------
    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self.params
        lim = obs.limits
        dt = float(obs.dt)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        path = PathTracker.normalise(obs.path, obs.goal_pose.xy)
        goal_xy = obs.goal_pose.xy
        if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
            path = np.vstack([path, goal_xy])  # the path may end on a grid cell near the goal
        tr = self._tracker
        s = tr.track(path, pose[:2])
        d_end = float(np.hypot(*(path[-1] - pose[:2])))
        car = obs.drive == "ackermann" or lim.min_turning_radius > 0
        if at_goal(obs, d_end, p.goal_tolerance):
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)

        samples = self.samples(obs)
        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        v_top = max(v_top, 1e-6)
        reach = max(v_top, float(np.max(np.abs(lim.upper[:2])))) * p.sim_time
        times = np.linspace(p.sim_time / p.steps, p.sim_time, p.steps)
        xs, ys, th = rollout(samples, times)
        n = len(samples)
        speed = np.hypot(samples[:, 0], samples[:, 1])

        # Obstacles: returns that the rollouts can reach, reduced to a voxel grid.
        pts = obs.scan_points()
        if len(pts):
            pts = pts[np.hypot(pts[:, 0], pts[:, 1]) <= reach + obs.robot_radius + 1.0]
            if len(pts):
                pts = np.unique(np.round(pts / p.voxel), axis=0) * p.voxel
        clear = np.full(n, np.inf)
        first = np.full(n, p.steps, dtype=np.int64)
        if len(pts):
            _clearance_kernel(np.ascontiguousarray(xs), np.ascontiguousarray(ys),
                              np.ascontiguousarray(pts), float(obs.robot_radius), clear, first)
        decel = p.decel_fraction * lim.acc_x
        t_safe = np.where(first > 0, times[np.maximum(first - 1, 0)], 0.0)
        d_free = np.where(first >= p.steps, np.inf, speed * t_safe)
        brake_ok = speed <= np.sqrt(2.0 * decel * np.maximum(d_free - p.stop_distance, 0.0))
        ok = (first >= p.steps) | brake_ok | (speed == 0.0)
        if len(pts):
            # Keep min_clearance to the returns, unless already closer (then do not get closer).
            now = float(np.min(np.hypot(pts[:, 0], pts[:, 1]))) - obs.robot_radius
            ok &= (speed == 0.0) | (clear >= min(p.min_clearance, now - 1e-3))

        # Goal braking: never faster than what stops at the path end.
        d_goal = max(tr.total - s, d_end)
        v_goal = stopping_speed(d_goal, decel)
        lo_speed = float(np.min(speed))
        ok &= speed <= max(v_goal, lo_speed) + 1e-9
        if not np.any(ok):
            return finish_command(np.zeros(3), twist, lim, dt, car)

        # Path and goal terms in the world frame.
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        ex = pose[0] + c * xs[:, -1] - sn * ys[:, -1]
        ey = pose[1] + sn * xs[:, -1] + c * ys[:, -1]
        end = np.stack([ex, ey], axis=-1)
        look = max(p.local_goal_distance, reach)
        s_goal = min(s + look, tr.total)
        goal_w = tr.point_at(s_goal)
        # Path term: mean distance to the path along the rollout (not only at its end, so arcs
        # that cut a corner pay for it).
        sub = slice(p.steps // 4, None, max(p.steps // 5, 1))
        wx = pose[0] + c * xs[:, sub] - sn * ys[:, sub]
        wy = pose[1] + sn * xs[:, sub] + c * ys[:, sub]
        along = np.stack([wx.ravel(), wy.ravel()], axis=-1)
        dist_along = tr.project(along, s, s_goal + reach)[0].reshape(n, -1)
        _, s_end = tr.project(end, s, s_goal + reach)
        goal_r = to_robot_frame(goal_w, pose)
        if s_goal >= tr.total - 1e-9:
            dist_all = np.hypot(xs - goal_r[0], ys - goal_r[1])
            goal_cost = np.minimum(np.min(dist_all, axis=1), np.hypot(goal_r[0], goal_r[1]))
            # Past its closest approach to the goal a rollout has arrived: ignore the rest.
            k_best = np.argmin(dist_all, axis=1)
            idx = np.arange(p.steps)[sub]
            use = idx[None, :] <= k_best[:, None]
            path_cost = (dist_along * use).sum(axis=1) / np.maximum(use.sum(axis=1), 1)
        else:
            goal_cost = s_goal - s_end
            path_cost = dist_along.mean(axis=1)
        to_goal = np.arctan2(goal_r[1] - ys[:, -1], goal_r[0] - xs[:, -1])
        heading_err = np.abs(np.angle(np.exp(1j * (to_goal - th[:, -1]))))
        heading_cost = heading_err / math.pi * np.minimum(1.0, goal_cost / 0.5)
        # Fade the soft obstacle term over the last `goal_fade` metres: goals are sampled with
        # clearance, and near a wall corner the term would otherwise outweigh the last bit of
        # progress (the robot stalls short of the goal). Safety stays with the hard checks.
        fade = min(1.0, d_goal / p.goal_fade) if p.goal_fade > 0 else 1.0
        obstacle_cost = fade * np.exp(-np.maximum(clear, 0.0) / p.obstacle_scale)
        forward = speed if (obs.drive == "omni" and lim.holonomic) else samples[:, 0]
        speed_cost = (v_top - forward) / v_top
        cost = (p.path_weight * path_cost + p.goal_weight * goal_cost
                + p.heading_weight * heading_cost + p.obstacle_weight * obstacle_cost
                + p.speed_weight * speed_cost)
        cost = np.where(ok, cost, np.inf)
        best = samples[int(np.argmin(cost))].copy()
        if car:
            return lim.clip(best)
        return limit_command(best, twist, lim, dt)

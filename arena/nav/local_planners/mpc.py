"""Nonlinear model-predictive control (MPC) with casadi's Opti stack and ipopt.

Description:
    Each tick the planner solves a finite-horizon optimal-control problem over ``horizon`` steps
    of ``step`` seconds for the unicycle / holonomic state ``[x m, y m, theta rad]`` (world
    frame) and the body-frame controls of the robot's kinematics:

    - ``diff_drive`` / ``legged``: ``u = [v, omega]``;
    - ``omni``: ``u = [vx, vy, omega]``;
    - ``ackermann``: ``u = [v, kappa]`` with the curvature ``|kappa| ≤ 1 / R_min`` (the turning
      radius) and ``omega = kappa · v``.

    The dynamics are integrated with the midpoint heading (``theta + omega · h / 2``), which is
    exact to second order for arcs.

    Cost (all weights per step unless noted):

    - ``track_weight ×`` squared distance (m²) of each predicted position to a reference
      sampled along the global path from the robot's projection at the cruise speed (capped
      by the braking speed to the goal, and clamped at the path end),
    - ``heading_weight × (1 - cos(theta - theta_ref))`` with ``theta_ref`` the path tangent at
      the reference point,
    - ``terminal_weight ×`` squared distance of the last predicted position to the last
      reference point (the goal once the horizon reaches it),
    - ``effort_weight × |u|²`` and ``smooth_weight × |u_k - u_{k-1}|²`` (the first step
      against the current twist),
    - ``slack_weight × (s + s²)`` for the obstacle slacks.

    Constraints: the velocity box of :class:`~arena.robots.limits.VelocityLimits`; the
    acceleration limit from the current twist over the control period ``obs.dt`` for the first
    control and over ``step`` between controls (car-like robots: on the speed only, their yaw
    rate follows the curvature); and, softly, a squared distance of at least
    ``(robot_radius + margin)²`` (minus a non-negative slack) from each of the ``obstacles``
    nearest clustered laser returns (world frame, held fixed over the horizon). Unused obstacle
    slots are parked far away.

    The Opti problem is built once per ``(kinematics, horizon, obstacles)`` and reused with
    ``opti.parameter`` values; every solve is warm-started from the previous solution shifted
    by one step (or, after :meth:`MPCPlanner.reset`, from a rollout of the current twist), so
    the output is a deterministic function of the observation sequence. ipopt runs with
    ``max_iter`` (no time limit) and is silent.

    Safety: the first control's speed is capped by the braking speed to the nearest laser
    return straight along its direction of motion. If ipopt fails (infeasible, iteration limit
    or numerical trouble) the planner brakes as hard as allowed and forgets its warm start.

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Dependencies:
    casadi (``pip install 'arena[mpc]'``), imported when the first planner is built.

Arguments:
    See :class:`MPCPlanner.Params`.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.core.types import wrap_angle_scalar
from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    stopping_speed,
)
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    at_goal,
    cluster_points,
    finish_command,
    free_distance,
    goal_command,
)

_FAR = 1.0e3  # m, where unused obstacle slots are parked (relative to the robot)


def _import_casadi() -> Any:
    """Import casadi lazily; a :class:`ConfigError` explains how to install it if missing."""
    try:
        import casadi
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ConfigError("the mpc planner needs casadi: pip install 'arena[mpc]'") from exc
    return casadi


class _Problem:
    """One parametrised Opti problem for a kinematics, horizon and obstacle count."""

    def __init__(self, ca: Any, kind: str, n: int, k: int, params: MPCPlanner.Params) -> None:
        self.kind = kind
        self.n = n
        self.k = k
        nu = 3 if kind == "omni" else 2
        self.nu = nu
        opti = ca.Opti()
        self.opti = opti
        x = opti.variable(3, n + 1)
        u = opti.variable(nu, n)
        s = opti.variable(max(k, 1), n)
        self.x, self.u, self.s = x, u, s
        # Parameters.
        self.p_x0 = opti.parameter(3)
        self.p_u0 = opti.parameter(nu)  # current twist in control coordinates
        self.p_ref = opti.parameter(3, n)  # x, y, theta of the reference at steps 1..n
        self.p_obs = opti.parameter(2, max(k, 1))
        self.p_lo = opti.parameter(nu)
        self.p_hi = opti.parameter(nu)
        self.p_acc0 = opti.parameter(nu)  # velocity change allowed over the first step
        self.p_acc = opti.parameter(nu)  # ... between later steps
        self.p_rsafe2 = opti.parameter()
        h = params.step
        opti.subject_to(x[:, 0] == self.p_x0)
        cost = 0
        for i in range(n):
            th = x[2, i]
            if nu == 3:
                vx, vy, w = u[0, i], u[1, i], u[2, i]
            elif kind == "ackermann":
                vx, vy, w = u[0, i], 0, u[0, i] * u[1, i]  # u = [v, curvature]
            else:
                vx, vy, w = u[0, i], 0, u[1, i]
            mid = th + 0.5 * h * w
            c, sn = ca.cos(mid), ca.sin(mid)
            opti.subject_to(x[0, i + 1] == x[0, i] + h * (c * vx - sn * vy))
            opti.subject_to(x[1, i + 1] == x[1, i] + h * (sn * vx + c * vy))
            opti.subject_to(x[2, i + 1] == th + h * w)
            # Velocity box and acceleration.
            opti.subject_to(opti.bounded(self.p_lo, u[:, i], self.p_hi))
            prev = self.p_u0 if i == 0 else u[:, i - 1]
            room = self.p_acc0 if i == 0 else self.p_acc
            rows = [0] if kind == "ackermann" else list(range(nu))
            for r in rows:
                opti.subject_to(opti.bounded(-room[r], u[r, i] - prev[r], room[r]))
            # Obstacles (soft).
            if k > 0:
                for j in range(k):
                    dx = x[0, i + 1] - self.p_obs[0, j]
                    dy = x[1, i + 1] - self.p_obs[1, j]
                    opti.subject_to(dx * dx + dy * dy + s[j, i] >= self.p_rsafe2)
            opti.subject_to(s[:, i] >= 0)
            # Cost.
            ex = x[0, i + 1] - self.p_ref[0, i]
            ey = x[1, i + 1] - self.p_ref[1, i]
            cost += params.track_weight * (ex * ex + ey * ey)
            cost += params.heading_weight * (1 - ca.cos(x[2, i + 1] - self.p_ref[2, i]))
            cost += params.effort_weight * ca.sumsqr(u[:, i])
            cost += params.smooth_weight * ca.sumsqr(u[:, i] - prev)
            cost += params.slack_weight * (ca.sum1(s[:, i]) + ca.sumsqr(s[:, i]))
        ex = x[0, n] - self.p_ref[0, n - 1]
        ey = x[1, n] - self.p_ref[1, n - 1]
        cost += params.terminal_weight * (ex * ex + ey * ey)
        opti.minimize(cost)
        opti.solver(
            "ipopt",
            {"print_time": False, "error_on_fail": True},
            {
                "max_iter": params.max_iter,
                "print_level": 0,
                "sb": "yes",
                "tol": params.tolerance,
                "acceptable_tol": 10 * params.tolerance,
            },
        )


_USABLE_STATUS = frozenset(
    {"Solve_Succeeded", "Solved_To_Acceptable_Level", "Maximum_Iterations_Exceeded"}
)
"""ipopt outcomes whose iterate is used (clipped and speed-capped) rather than braking."""


@LOCAL_PLANNERS.register("mpc", tags=("optimisation", "casadi"))
class MPCPlanner:
    """Nonlinear MPC local planner (casadi Opti + ipopt); see the module docstring.

    Args:
        params: validated :class:`MPCPlanner.Params` (defaults if omitted).

    Raises:
        ConfigError: casadi is not installed.
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of :class:`MPCPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        horizon: int = Field(12, ge=2, le=60, description="prediction steps")
        step: float = Field(0.2, gt=0, description="s, duration of one prediction step")
        obstacles: int = Field(10, ge=0, le=64, description="clustered laser returns avoided")
        cluster_radius: float = Field(
            0.25, gt=0, description="m, laser returns within this of a kept one are merged"
        )
        margin: float = Field(0.1, ge=0, description="m, clearance added to the robot radius")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        track_weight: float = Field(2.0, ge=0, description="1/m², path tracking weight")
        heading_weight: float = Field(0.3, ge=0, description="weight of the heading term")
        terminal_weight: float = Field(10.0, ge=0, description="1/m², terminal weight")
        effort_weight: float = Field(0.02, ge=0, description="weight of |u|²")
        smooth_weight: float = Field(0.3, ge=0, description="weight of |Δu|²")
        slack_weight: float = Field(500.0, gt=0, description="weight of the obstacle slacks")
        max_iter: int = Field(60, ge=1, description="ipopt iteration limit (deterministic)")
        tolerance: float = Field(1e-4, gt=0, description="ipopt convergence tolerance")
        stop_distance: float = Field(
            0.1, ge=0, description="m, gap to a laser return straight ahead at which it stops"
        )
        decel_fraction: float = Field(
            0.8, gt=0, le=1, description="share of the acceleration limit used for braking"
        )
        goal_tolerance: float = Field(
            0.05, gt=0, description="m, distance to the path end at which the planner stops"
        )
        heading_gain: float = Field(
            2.0, gt=0, description="1/s, proportional gain of in-place goal alignment"
        )
        goal_yaw_tolerance: float = Field(
            0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._ca = _import_casadi()
        self._problems: dict[tuple[str, int, int], _Problem] = {}
        self._tracker = PathTracker()
        self.failures = 0
        """Number of solver failures since construction (braking fallbacks)."""
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path and the warm start."""
        self._tracker.reset()
        self._warm: tuple[str, NDArray[np.float64], NDArray[np.float64]] | None = None

    def _problem(self, kind: str) -> _Problem:
        p = self.params
        key = (kind, p.horizon, p.obstacles)
        if key not in self._problems:
            self._problems[key] = _Problem(self._ca, kind, p.horizon, p.obstacles, p)
        return self._problems[key]

    # -- control ----------------------------------------------------------------------------------
    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self.params
        lim = obs.limits
        dt = float(obs.dt)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        drive = obs.drive
        car = drive == "ackermann" or lim.min_turning_radius > 0
        kind = "ackermann" if car else ("omni" if drive == "omni" and lim.holonomic else "diff")
        path = PathTracker.normalise(obs.path, obs.goal_pose.xy)
        goal_xy = obs.goal_pose.xy
        if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
            path = np.vstack([path, goal_xy])
        tr = self._tracker
        s0 = tr.track(path, pose[:2])
        d_end = float(np.hypot(*(path[-1] - pose[:2])))
        if at_goal(obs, d_end, p.goal_tolerance):
            self._warm = None
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)

        prob = self._problem(kind)
        n, h = p.horizon, p.step
        decel = p.decel_fraction * lim.acc_x
        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        d_goal = max(tr.total - s0, d_end)
        v_ref = max(min(v_top, stopping_speed(d_goal, decel)), 0.05)
        s_ref = s0 + v_ref * h * np.arange(1, n + 1, dtype=np.float64)
        ref_xy = tr.point_at(s_ref)
        ref_th = np.array([tr.tangent_at(float(si)) for si in s_ref])
        # Unwrap the reference heading near the robot's heading (cos is periodic anyway, but the
        # solver's initial guess behaves better).
        ref_th = pose[2] + np.array([wrap_angle_scalar(float(t - pose[2])) for t in ref_th])

        # Obstacles: nearest clustered returns, robot frame → world frame.
        r_safe = obs.robot_radius + p.margin
        far = np.tile(pose[:2, None] + _FAR, (1, max(p.obstacles, 1)))
        pts = obs.scan_points()
        if p.obstacles > 0 and len(pts):
            reach = v_top * h * n + r_safe + 0.5
            cl = cluster_points(pts, p.obstacles, p.cluster_radius, reach)
            c, sn = math.cos(pose[2]), math.sin(pose[2])
            world = np.stack([pose[0] + c * cl[:, 0] - sn * cl[:, 1],
                              pose[1] + sn * cl[:, 0] + c * cl[:, 1]])
            far[:, : world.shape[1]] = world

        # Bounds in control coordinates.
        idx = [0, 1, 2] if kind == "omni" else [0, 2]
        lo, hi = lim.lower[idx], lim.upper[idx]
        acc = lim.acceleration[idx]
        ca_u0 = twist[idx]
        if kind == "ackermann":
            # Controls [v, curvature]: the turning radius is a box on the curvature.
            r = lim.min_turning_radius
            k_max = 1.0 / r if r > 0 else 1e3
            lo[1], hi[1], acc[1] = -k_max, k_max, 1e3
            ca_u0 = np.array([twist[0], twist[2] / twist[0] if abs(twist[0]) > 1e-6 else 0.0])
            ca_u0[1] = float(np.clip(ca_u0[1], -k_max, k_max))
        u_now = np.clip(ca_u0, lo, hi)
        # The first step must be reachable: if the twist is outside the box, widen the window.
        acc0 = acc * dt + np.maximum(np.maximum(ca_u0 - hi, lo - ca_u0), 0.0)
        opti = prob.opti
        opti.set_value(prob.p_x0, pose)
        opti.set_value(prob.p_u0, ca_u0)
        opti.set_value(prob.p_ref, np.vstack([ref_xy.T, ref_th]))
        opti.set_value(prob.p_obs, far)
        opti.set_value(prob.p_lo, lo)
        opti.set_value(prob.p_hi, hi)
        opti.set_value(prob.p_acc0, acc0)
        opti.set_value(prob.p_acc, acc * h)
        opti.set_value(prob.p_rsafe2, r_safe * r_safe)
        x_init, u_init = self._initial_guess(
            kind, pose, u_now, prob.nu, ref_th=ref_th, v_ref=v_ref, lo=lo, hi=hi, acc=acc * h
        )
        opti.set_initial(prob.x, x_init)
        opti.set_initial(prob.u, u_init)
        opti.set_initial(prob.s, np.zeros((max(p.obstacles, 1), n)))
        try:
            # solve_limited: an iterate that ran out of iterations is still used (it is
            # clipped to the limits and speed-capped by the laser below); only a solver error
            # or a non-finite result falls back to braking.
            sol = opti.solve_limited()
            status = str(opti.stats().get("return_status", ""))
            if status not in _USABLE_STATUS:
                raise RuntimeError(status)
            u_opt = np.asarray(sol.value(prob.u), dtype=np.float64).reshape(prob.nu, n)
            x_opt = np.asarray(sol.value(prob.x), dtype=np.float64).reshape(3, n + 1)
        except RuntimeError:
            self.failures += 1
            self._warm = None
            return finish_command(np.zeros(3), twist, lim, dt, car)
        if not (np.all(np.isfinite(u_opt)) and np.all(np.isfinite(x_opt))):
            self.failures += 1
            self._warm = None
            return finish_command(np.zeros(3), twist, lim, dt, car)
        self._warm = (kind, x_opt, u_opt)
        cmd = np.zeros(3)
        cmd[idx] = u_opt[:, 0]
        if kind == "ackermann":
            cmd[2] = u_opt[0, 0] * u_opt[1, 0]
        cmd = self._safety(cmd, obs, pts, decel)
        return finish_command(cmd, twist, lim, dt, car)

    def _initial_guess(
        self,
        kind: str,
        pose: NDArray[np.float64],
        u_now: NDArray[np.float64],
        nu: int,
        *,
        ref_th: NDArray[np.float64],
        v_ref: float,
        lo: NDArray[np.float64],
        hi: NDArray[np.float64],
        acc: NDArray[np.float64],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(3, N+1)`` states and ``(nu, N)`` controls for ipopt to start from.

        The shifted last solution, or (cold start) a rollout that turns toward the reference
        heading and speeds up to ``v_ref`` within the limits: starting from rest makes ipopt
        slow (out of iterations) when the robot must first turn.
        """
        n, h = self.params.horizon, self.params.step
        warm = self._warm is not None and self._warm[0] == kind
        u = np.zeros((nu, n))
        if warm:
            assert self._warm is not None
            u_prev = self._warm[2]
            u = np.hstack([u_prev[:, 1:], u_prev[:, -1:]])
        x = np.zeros((3, n + 1))
        x[:, 0] = pose
        prev = u_now.copy()
        for i in range(n):
            if not warm:
                err = wrap_angle_scalar(float(ref_th[i] - x[2, i]))
                want = prev.copy()
                want[0] = v_ref * max(math.cos(err), 0.0)
                turn = err / max(h, 1e-6)
                if kind == "ackermann":
                    want[1] = turn / max(abs(want[0]), 0.1)
                else:
                    want[-1] = turn
                want = np.clip(want, prev - acc, prev + acc)
                u[:, i] = prev = np.clip(want, lo, hi)
            if nu == 3:
                vx, vy, w = u[0, i], u[1, i], u[2, i]
            elif kind == "ackermann":
                vx, vy, w = u[0, i], 0.0, u[0, i] * u[1, i]
            else:
                vx, vy, w = u[0, i], 0.0, u[1, i]
            mid = x[2, i] + 0.5 * h * w
            c, sn = math.cos(mid), math.sin(mid)
            x[:, i + 1] = x[:, i] + h * np.array([c * vx - sn * vy, sn * vx + c * vy, w])
        return x, u

    def _safety(
        self, cmd: NDArray[np.float64], obs: LocalObservation, pts: NDArray[np.float64],
        decel: float,
    ) -> NDArray[np.float64]:
        """Cap the speed of ``cmd`` by the braking speed to the nearest return along its motion."""
        speed = float(math.hypot(cmd[0], cmd[1]))
        if speed < 1e-9 or len(pts) == 0:
            return cmd
        direction = np.array([cmd[0], cmd[1]]) / speed
        gap = free_distance(pts, direction, obs.robot_radius)
        v_max = stopping_speed(gap - self.params.stop_distance, decel)
        if speed > v_max:
            out = cmd.copy()
            out[:2] *= v_max / speed
            if obs.drive == "ackermann" or obs.limits.min_turning_radius > 0:
                out[2] *= v_max / speed  # keep the curvature
            return out
        return cmd



"""Timed Elastic Band (Rösmann et al. 2012/2017; as in ROS ``teb_local_planner``).

Description:
    The planner keeps a *band* of poses ``s_i = (x_i, y_i, θ_i)``, ``i = 0..N``, joined by time
    intervals ``ΔT_i`` (s) — a trajectory in space and time. Each control cycle:

    1. **Band.** The local goal is the global-path point ``horizon`` metres ahead of the robot's
       projection (the goal itself when closer). The band starts at the robot's pose; it is
       warm-started from the previous cycle's band (the part already passed is pruned, the rest
       is extended along the path to the new local goal), or else laid along the path. It is
       resampled to ``N = clip(length / segment, min_poses, max_poses)`` segments; ``ΔT_i`` is
       the segment length over the cruise speed (or the previous band's timing).
    2. **Optimisation.** The free variables (inner poses, the last heading, all ``ΔT``) minimise
       a sum of squared penalties with :func:`scipy.optimize.least_squares` (``trf``, sparse
       finite-difference Jacobian from ``jac_sparsity``, fixed ``max_nfev`` per outer iteration,
       ``outer_iterations`` rounds — so the result is deterministic). Each penalty is a residual
       ``√w · e`` with, per segment or pose:

       - time optimality: ``e = ΔT_i`` (``time_weight``);
       - velocity limits: hinge on the body velocities of each segment beyond the velocity box
         shrunk by ``penalty_epsilon`` (``velocity_weight``);
       - acceleration limits: hinge on the velocity change between segments, from the current
         twist at the start and to rest at the final goal (``acceleration_weight``);
       - non-holonomic kinematics (not for ``omni``): ``e = (cos θ_i + cos θ_{i+1}) Δy − (sin θ_i
         + sin θ_{i+1}) Δx`` — equal heading angles to the segment, i.e. an arc
         (``kinematics_weight``), plus a hinge against driving backwards
         (``forward_drive_weight``); car-like robots add a hinge ``|Δθ| − Δs / R_min``
         (``turning_radius_weight``);
       - obstacles: hinge ``robot_radius + min_obstacle_dist − d`` on the distance of every
         inner pose to up to ``obstacle_points`` clustered laser returns (``obstacle_weight``);
       - path following (via-points): distance of every inner pose to the local path
         (``path_weight``);
       - dynamic obstacles: for every pedestrian in :attr:`LocalObservation.pedestrians`, the
         position predicted at the pose's time stamp (constant velocity; stamps frozen per outer
         iteration, as in TEB) must stay ``robot_radius + ped_radius + min_obstacle_dist`` away
         (``dynamic_obstacle_weight``).

       Subclasses add residuals through :meth:`TEBPlanner.extra_residuals` (see
       :mod:`arena.nav.local_planners.cohan`).
    3. **Command.** The velocity of the first band segment (body frame), capped by the braking
       speed to the goal and to the nearest laser return ahead, and limited with
       :func:`~arena.nav.local_planners.base.limit_command`; car-like robots keep
       ``|ω| ≤ |vx| / R_min``. Robots that can turn on the spot first turn toward the band when
       its first segment points more than ``turn_in_place_angle`` away.

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Arguments:
    See :class:`TEBPlanner.Params`.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from scipy.optimize import least_squares
from scipy.sparse import coo_matrix

from arena.core.geometry import polyline_length, segment_lengths
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
from arena.nav.local_planners.teb_band import (
    _FD_STEP,
    Band,
    BandContext,
    FloatArray,
    IntArray,
    _column_groups,
    _hinge,
    _resample,
)
from arena.robots.limits import VelocityLimits


@LOCAL_PLANNERS.register("teb", tags=("classic", "optimisation"))
class TEBPlanner:
    """Timed-Elastic-Band local planner (trajectory optimisation in space and time).

    Args:
        params: validated :class:`TEBPlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of :class:`TEBPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        horizon: float = Field(3.5, gt=0, description="m, band length along the global path")
        segment: float = Field(0.2, gt=0, description="m, reference distance between poses")
        min_poses: int = Field(4, ge=2, description="fewest band segments")
        max_poses: int = Field(20, ge=2, le=100, description="most band segments")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        solver: Literal["grouped", "lsmr", "exact"] = Field(
            "grouped", description="Jacobian and trust-region solver: 'grouped' (forward "
            "differences over column groups of the sparsity pattern, computed here with little "
            "overhead; LSMR steps), 'lsmr' (the same through scipy's jac_sparsity; slower for "
            "bands this small) or 'exact' (grouped Jacobian, SVD steps; fast only with "
            "single-threaded BLAS)",
        )
        lsmr_iterations: int = Field(
            20, ge=1, description="iteration cap of each LSMR trust-region subproblem"
        )
        max_nfev: int = Field(5, ge=1, description="function evaluations per outer iteration")
        outer_iterations: int = Field(
            2, ge=1, description="optimisation rounds (pedestrian time stamps refreshed)"
        )
        time_weight: float = Field(1.0, ge=0, description="weight of Σ ΔT² (s²)")
        spacing_weight: float = Field(
            100.0, ge=0, description="weight of the hinge on segments longer than 1.5 × the "
            "initial spacing (keeps poses dense so the band cannot jump over an obstacle)",
        )
        velocity_weight: float = Field(50.0, ge=0, description="weight of velocity-limit hinges")
        acceleration_weight: float = Field(
            5.0, ge=0, description="weight of acceleration-limit hinges"
        )
        kinematics_weight: float = Field(
            300.0, ge=0, description="weight of the non-holonomic (arc) constraint"
        )
        forward_drive_weight: float = Field(
            2.0, ge=0, description="weight of the hinge against backward motion"
        )
        turning_radius_weight: float = Field(
            50.0, ge=0, description="weight of the minimum-turning-radius hinge (car-like)"
        )
        obstacle_weight: float = Field(50.0, ge=0, description="weight of obstacle hinges")
        path_weight: float = Field(
            1.0, ge=0, description="weight of the distance to the path (via-points)"
        )
        dynamic_obstacle_weight: float = Field(
            50.0, ge=0, description="weight of predicted-pedestrian hinges"
        )
        min_obstacle_dist: float = Field(
            0.15, ge=0, description="m, clearance kept from laser returns beyond robot_radius"
        )
        ped_radius: float = Field(0.3, ge=0, description="m, radius assumed for pedestrians")
        penalty_epsilon: float = Field(
            0.05, ge=0, description="margin (m/s, rad/s) inside the velocity limits"
        )
        obstacles_per_pose: int = Field(
            3, ge=1, description="nearest obstacle points each pose is kept away from"
        )
        obstacle_points: int = Field(
            30, ge=0, description="most clustered laser returns the band considers"
        )
        cluster_radius: float = Field(
            0.15, gt=0, description="m, laser returns within this of a kept one are dropped"
        )
        ped_range: float = Field(
            6.0, gt=0, description="m, pedestrians farther than this from the robot are ignored"
        )
        stop_distance: float = Field(
            0.05, ge=0, description="m, clearance kept when braking before a laser return"
        )
        graze: float = Field(
            0.03, ge=0, description="m, laser returns this close to the edge of the robot's "
            "path do not stop it (the speed cap of the command)",
        )
        decel_fraction: float = Field(
            0.8, gt=0, le=1, description="share of the acceleration limit used for braking"
        )
        turn_in_place_angle: float = Field(
            1.2, gt=0, description="rad, heading error beyond which spot-turners turn first"
        )
        backoff_speed: float = Field(
            0.2, gt=0, description="m/s, speed of backing away from a return the robot touches"
        )
        lookahead: float = Field(
            0.5, gt=0, description="m along the band a blocked robot turns toward"
        )
        allow_reverse: bool = Field(False, description="let the band drive backwards")
        goal_tolerance: float = Field(
            0.05, gt=0, description="m, distance to the path end at which the planner stops"
        )
        heading_gain: float = Field(2.0, gt=0, description="1/s, gain of in-place turning")
        goal_yaw_tolerance: float = Field(
            0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
        )

    def __init__(self, params: BaseModel | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._tracker = PathTracker()
        self.band: Band | None = None
        self.reset()

    def reset(self) -> None:
        """Forget the band and the progress along the path."""
        self._tracker.reset()
        self.band = None
        self._band_end: FloatArray | None = None

    @property
    def _p(self) -> TEBPlanner.Params:
        return self.params  # type: ignore[return-value]

    # -- residuals ------------------------------------------------------------------------------
    def residuals(
        self, z: FloatArray, ctx: BandContext,
        groups: list[tuple[IntArray, IntArray, IntArray]] | None = None,
    ) -> FloatArray:
        """All weighted residuals ``(m,)`` of the variables ``z`` (see module docstring).

        ``groups`` is ignored (it lets the residuals and the Jacobian share ``args``).
        """
        p = self._p
        lim = ctx.limits
        n = ctx.n
        pos, th, dt = ctx.unpack(z)
        d = np.diff(pos, axis=0)
        c, s = np.cos(th), np.sin(th)
        inv = 1.0 / np.maximum(dt, 1e-6)
        dth = np.diff(th)
        vx = (d[:, 0] * c[:-1] + d[:, 1] * s[:-1]) * inv
        vy = (-d[:, 0] * s[:-1] + d[:, 1] * c[:-1]) * inv
        om = dth * inv
        eps = p.penalty_epsilon
        seg_len = np.hypot(d[:, 0], d[:, 1])
        out: list[FloatArray] = [
            math.sqrt(p.time_weight) * dt,
            math.sqrt(p.spacing_weight) * _hinge(seg_len - ctx.max_segment),
        ]
        wv = math.sqrt(p.velocity_weight)
        vx_lo = lim.vx_min if p.allow_reverse or ctx.drive == "omni" else 0.0
        out.append(wv * (_hinge(vx - (lim.vx_max - eps)) + _hinge(min(vx_lo + eps, 0.0) - vx)))
        out.append(wv * _hinge(np.abs(om) - max(lim.omega_max - eps, 0.0)))
        omni = ctx.drive == "omni"
        if omni:
            out.append(wv * (_hinge(vy - max(lim.vy_max - eps, 0.0))
                             + _hinge(min(lim.vy_min + eps, 0.0) - vy)))
        # Accelerations: from the current twist, between segments, to rest at the goal.
        mid = np.concatenate([[dt[0]], 0.5 * (dt[:-1] + dt[1:]), [dt[-1]]])
        wa = math.sqrt(p.acceleration_weight)
        chans = [(vx, float(ctx.twist[0]), lim.acc_x), (om, float(ctx.twist[2]), lim.acc_omega)]
        if omni:
            chans.append((vy, float(ctx.twist[1]), lim.acc_y))
        for v, v0, acc in chans:
            v_end = 0.0 if ctx.final else v[-1]
            dv = np.diff(np.concatenate([[v0], v, [v_end]])) / mid
            if ctx.drive == "ackermann" and v is om:
                continue
            out.append(wa * _hinge(np.abs(dv) - acc))
        if not omni:
            nh = (c[:-1] + c[1:]) * d[:, 1] - (s[:-1] + s[1:]) * d[:, 0]
            out.append(math.sqrt(p.kinematics_weight) * nh)
            if not p.allow_reverse:
                back = _hinge(-(d[:, 0] * c[:-1] + d[:, 1] * s[:-1]))
                out.append(math.sqrt(p.forward_drive_weight) * back)
            if ctx.drive == "ackermann" and lim.min_turning_radius > 0:
                ds = np.hypot(d[:, 0], d[:, 1])
                out.append(math.sqrt(p.turning_radius_weight)
                           * _hinge(np.abs(dth) - ds / lim.min_turning_radius))
        inner = pos[1:n]
        if len(ctx.obstacles):
            diff = inner[:, None, :] - ctx.obstacles[ctx.obstacle_idx]
            dist = np.sqrt(np.einsum("ikj,ikj->ik", diff, diff))
            out.append(math.sqrt(p.obstacle_weight)
                       * _hinge(ctx.radius + p.min_obstacle_dist - dist).ravel())
        diff = inner[:, None, :] - ctx.path[None, :, :]
        out.append(math.sqrt(p.path_weight)
                   * np.sqrt(np.min(np.einsum("ikj,ikj->ik", diff, diff), axis=1)))
        if len(ctx.peds):
            rel = inner[:, None, :] - ctx.ped_pred[1:n]
            dist = np.sqrt(np.einsum("ijk,ijk->ij", rel, rel))
            safe = ctx.radius + p.ped_radius + p.min_obstacle_dist
            out.append(math.sqrt(p.dynamic_obstacle_weight) * _hinge(safe - dist).ravel())
        out.extend(self.extra_residuals(pos, th, dt, ctx))
        return np.concatenate(out)

    def _grouped_jacobian(
        self, z: FloatArray, ctx: BandContext, groups: list[tuple[IntArray, IntArray, IntArray]]
    ) -> FloatArray:
        """Dense forward-difference Jacobian using column groups of the sparsity pattern.

        Columns in one group share no residual row, so one residual evaluation per group gives
        all their derivatives (Curtis–Powell–Reid), as ``least_squares(jac_sparsity=...)`` does.
        """
        f0 = self.residuals(z, ctx)
        jac = np.zeros((len(f0), len(z)))
        h = _FD_STEP * np.maximum(1.0, np.abs(z))
        for cols, rows, owner in groups:
            dz = np.zeros_like(z)
            dz[cols] = h[cols]
            df = self.residuals(z + dz, ctx, None) - f0
            jac[rows, owner] = df[rows] / h[owner]
        return jac

    def extra_residuals(
        self, pos: FloatArray, th: FloatArray, dt: FloatArray, ctx: BandContext
    ) -> list[FloatArray]:
        """Extra residual blocks of subclasses (none here).

        Their rows must match :meth:`extra_dependencies`.
        """
        return []

    def extra_dependencies(self, ctx: BandContext) -> list[IntArray]:
        """Per extra block, ``(rows, k)`` variable columns each row uses (−1 = none)."""
        return []

    def dependencies(self, ctx: BandContext) -> list[IntArray]:
        """Per residual block of :meth:`residuals`, ``(rows, k)`` columns each row uses."""
        p = self._p
        n = ctx.n
        seg = np.arange(n)
        sd = ctx.segment_deps(seg)
        blocks: list[IntArray] = [ctx.dt_col(seg)[:, None], sd, sd, sd]
        omni = ctx.drive == "omni"
        if omni:
            blocks.append(sd)
        # Acceleration rows j = 0..N: segments j-1 and j (clamped).
        j = np.arange(n + 1)
        acc = np.hstack([ctx.segment_deps(np.clip(j - 1, 0, n - 1)),
                         ctx.segment_deps(np.clip(j, 0, n - 1))])
        blocks.append(acc)
        if ctx.drive != "ackermann":
            blocks.append(acc)
        if omni:
            blocks.append(acc)
        if not omni:
            blocks.append(sd)
            if not p.allow_reverse:
                blocks.append(sd)
            if ctx.drive == "ackermann" and ctx.limits.min_turning_radius > 0:
                blocks.append(sd)
        inner = np.arange(1, n)
        pdeps = ctx.pose_deps(inner)
        if len(ctx.obstacles):
            blocks.append(np.repeat(pdeps, ctx.obstacle_idx.shape[1], axis=0))
        blocks.append(pdeps)
        if len(ctx.peds):
            blocks.append(np.repeat(pdeps, len(ctx.peds), axis=0))
        blocks.extend(self.extra_dependencies(ctx))
        return blocks

    def sparsity(self, ctx: BandContext) -> coo_matrix:
        """Jacobian sparsity pattern ``(m, size)`` of :meth:`residuals`."""
        rows: list[IntArray] = []
        cols: list[IntArray] = []
        offset = 0
        for deps in self.dependencies(ctx):
            r = np.repeat(np.arange(offset, offset + len(deps)), deps.shape[1])
            cc = deps.ravel()
            ok = cc >= 0
            rows.append(r[ok])
            cols.append(cc[ok])
            offset += len(deps)
        rr, cc2 = np.concatenate(rows), np.concatenate(cols)
        return coo_matrix((np.ones(len(rr)), (rr, cc2)), shape=(offset, ctx.size))

    # -- band -----------------------------------------------------------------------------------
    def _initial_band(
        self, pose: FloatArray, local: FloatArray, v_ref: float, drive: str
    ) -> Band:
        """Band from ``pose`` along the local path ``local`` ``(k, 2)``, warm-started."""
        p = self._p
        pts = np.vstack([pose[None, :2], local])
        prev = self.band
        if prev is not None and self._band_end is not None:
            old = prev.poses[:, :2]
            k = int(np.argmin(np.hypot(*(old - pose[:2]).T)))
            far = np.hypot(*(old[k] - pose[:2]))
            if far < 0.5:
                rest = old[k + 1:]
                # Continue from the old band's end along the path to the new local goal.
                dl = np.hypot(*(local - rest[-1]).T) if len(rest) else None
                if dl is not None and float(np.min(dl)) < 0.5:
                    j = int(np.argmin(dl))
                    pts = np.vstack([pose[None, :2], rest, local[j + 1:]])
        length = polyline_length(pts)
        n = int(np.clip(round(length / p.segment), p.min_poses, p.max_poses))
        xy, _ = _resample(pts, n + 1)
        xy[-1] = local[-1]
        d = np.diff(xy, axis=0)
        ang = np.arctan2(d[:, 1], d[:, 0])
        if drive == "omni":
            th = np.full(n + 1, float(pose[2]))
        else:
            th = np.empty(n + 1)
            th[0] = pose[2]
            heading = np.concatenate([ang, ang[-1:]])
            for i in range(1, n + 1):
                th[i] = th[i - 1] + wrap_angle_scalar(float(heading[i]) - th[i - 1])
        seg = np.linalg.norm(d, axis=1)
        dt = np.maximum(seg / max(v_ref, 1e-3), 0.02)
        return Band(np.column_stack([xy, th]), dt)

    # -- control ----------------------------------------------------------------------------------
    def compute(self, obs: LocalObservation) -> FloatArray:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self._p
        lim = obs.limits
        dt = float(obs.dt)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        goal_xy = obs.goal_pose.xy
        path = PathTracker.normalise(obs.path, goal_xy)
        if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
            path = np.vstack([path, goal_xy])
        tr = self._tracker
        s = tr.track(path, pose[:2])
        d_end = float(np.hypot(*(path[-1] - pose[:2])))
        drive = obs.drive
        car = drive == "ackermann" or lim.min_turning_radius > 0
        if car:
            drive = "ackermann"
        elif drive == "omni" and not lim.holonomic:
            drive = "diff_drive"
        if at_goal(obs, d_end, p.goal_tolerance):
            self.band = None
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)

        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        v_top = max(v_top, 1e-3)
        s_end = min(s + p.horizon, tr.total)
        final = s_end >= tr.total - 1e-9
        m = max(math.ceil((s_end - s) / 0.05), 1) + 1
        local = tr.point_at(np.linspace(s, s_end, m))
        if final:
            local[-1] = path[-1]
        if np.hypot(*(local[-1] - pose[:2])) < 1e-3:
            return finish_command(np.zeros(3), twist, lim, dt, car)
        band = self._initial_band(pose, local, v_top, drive)
        n = len(band.dt)

        # Obstacles (world frame) and pedestrians near the robot.
        pts = obs.scan_points()
        c0, s0 = math.cos(pose[2]), math.sin(pose[2])
        rot = np.array([[c0, s0], [-s0, c0]])
        reach = p.horizon + obs.robot_radius + p.min_obstacle_dist + 0.5
        clustered = (cluster_points(pts, p.obstacle_points, p.cluster_radius, reach)
                     if len(pts) and p.obstacle_points > 0 else np.zeros((0, 2)))
        obstacles = clustered @ rot + pose[:2]
        peds = np.asarray(obs.pedestrians, dtype=np.float64).reshape(-1, 4)
        if len(peds):
            peds = peds[np.all(np.isfinite(peds), axis=1)]
            peds = peds[np.hypot(*(peds[:, :2] - pose[:2]).T) <= p.ped_range]

        lower = np.full(4 * n - 2, -np.inf)
        upper = np.full(4 * n - 2, np.inf)
        lower[3 * n - 2:] = 0.01
        upper[3 * n - 2:] = 5.0
        band.dt = np.clip(band.dt, 0.011, 4.99)
        ctx = BandContext(
            n=n, start=pose.copy(), end=band.poses[-1, :2].copy(), twist=twist, final=final,
            drive=drive, limits=lim, radius=float(obs.robot_radius), obstacles=obstacles,
            obstacle_idx=np.zeros((n - 1, 0), dtype=np.int64),
            max_segment=1.5 * float(np.max(segment_lengths(band.poses))),
            path=local, times=band.times, peds=peds,
            ped_pred=self._predict(peds, band.times),
        )
        z = ctx.pack(band)
        for _ in range(p.outer_iterations):
            cur_pos, _, cur_dt = ctx.unpack(z)
            ctx.times = np.concatenate([[0.0], np.cumsum(cur_dt)])
            ctx.ped_pred = self._predict(peds, ctx.times)
            if len(obstacles):
                k = min(p.obstacles_per_pose, len(obstacles))
                rel = cur_pos[1:n, None, :] - obstacles[None, :, :]
                d2 = np.einsum("ikj,ikj->ik", rel, rel)
                ctx.obstacle_idx = np.argsort(d2, axis=1, kind="stable")[:, :k]
            pattern = self.sparsity(ctx)
            try:
                if p.solver == "lsmr":
                    res = least_squares(self.residuals, z, jac_sparsity=pattern, method="trf",
                                        tr_solver="lsmr", bounds=(lower, upper),
                                        tr_options={"maxiter": p.lsmr_iterations},
                                        max_nfev=p.max_nfev, args=(ctx,))
                else:
                    groups = _column_groups(pattern)
                    exact = p.solver == "exact"
                    res = least_squares(self.residuals, z, jac=self._grouped_jacobian,
                                        method="trf", tr_solver="exact" if exact else "lsmr",
                                        tr_options={} if exact else {
                                            "maxiter": p.lsmr_iterations},
                                        bounds=(lower, upper), max_nfev=p.max_nfev,
                                        args=(ctx, groups))
            except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
                break
            if np.all(np.isfinite(res.x)):
                z = np.asarray(res.x, dtype=np.float64)
        pos, th, dts = ctx.unpack(z)
        self.band = Band(np.column_stack([pos, th]), dts.copy())
        self._band_end = pos[-1].copy()
        return self._command(obs, pose, twist, clustered, tr.total - s, d_end, car, v_top)

    @staticmethod
    def _predict(peds: FloatArray, times: FloatArray) -> FloatArray:
        """``(N+1, J, 2)`` constant-velocity positions (m) of ``peds`` at ``times`` (s)."""
        if len(peds) == 0:
            return np.zeros((len(times), 0, 2))
        return peds[None, :, :2] + times[:, None, None] * peds[None, :, 2:4]

    def _command(
        self, obs: LocalObservation, pose: FloatArray, twist: FloatArray, pts: FloatArray,
        left: float, d_end: float, car: bool, v_top: float,
    ) -> FloatArray:
        """Velocity of the band's first segment, made safe and feasible (body frame)."""
        p = self._p
        lim = obs.limits
        dt = float(obs.dt)
        assert self.band is not None
        band = self.band
        d = band.poses[1, :2] - pose[:2]
        step = max(float(band.dt[0]), 1e-3)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        vx = (c * d[0] + s * d[1]) / step
        vy = (-s * d[0] + c * d[1]) / step
        om = (band.poses[1, 2] - pose[2]) / step
        holo = obs.drive == "omni" and lim.holonomic and not car
        if not holo:
            vy = 0.0
        cmd = np.array([vx, vy, om])
        if not car and not holo:
            err = wrap_angle_scalar(math.atan2(d[1], d[0]) - float(pose[2]))
            if abs(err) > p.turn_in_place_angle and np.hypot(*d) > 1e-3:
                cmd = np.array([0.0, 0.0, p.heading_gain * err])
        # Never faster than what stops at the goal, or before the nearest return ahead.
        decel = p.decel_fraction * lim.acc_x
        speed = float(np.hypot(cmd[0], cmd[1]))
        cap = stopping_speed(max(left, d_end), decel)
        if speed > 1e-9 and len(pts):
            direction = cmd[:2] / speed
            # Grazing returns (within ``graze`` of the disc's edge) do not block: the band's
            # obstacle term steers clear of them, and blocking on them can stall the robot.
            free = free_distance(pts, direction, max(obs.robot_radius - p.graze, 0.0))
            cap = min(cap, stopping_speed(free - p.stop_distance, decel))
        cap = min(cap, v_top)
        if speed > cap:
            unit = cmd[:2] / speed
            scale = cap / speed
            cmd[:2] *= scale
            if car:
                cmd[2] *= scale
            if scale < 0.5 and self._in_contact(pts, obs.robot_radius + p.stop_distance, unit):
                # (Nearly) touching a return ahead (a person stepped in, a grazed corner):
                # back away from it where the robot can, else stay put and turn.
                back = self._back_off(pts, lim, holo)
                if back is not None:
                    return finish_command(back, twist, lim, dt, car)
            if not car and not holo and scale < 0.5:
                # Blocked straight ahead: turn toward where the band goes further on.
                ahead = np.cumsum(segment_lengths(band.poses))
                j = min(int(np.searchsorted(ahead, p.lookahead)) + 1, len(band.poses) - 1)
                far = band.poses[j, :2] - pose[:2]
                err = wrap_angle_scalar(math.atan2(far[1], far[0]) - float(pose[2]))
                cmd[2] = p.heading_gain * err
        return finish_command(cmd, twist, lim, dt, car)

    @staticmethod
    def _in_contact(pts: FloatArray, radius: float, direction: FloatArray) -> bool:
        """Whether a return of ``pts`` ``(m, 2)`` (robot frame, m) touches the robot ahead.

        Ahead means inside the disc of ``radius`` (m) on the side of the unit ``direction``.
        """
        if len(pts) == 0:
            return False
        d = np.hypot(pts[:, 0], pts[:, 1])
        return bool(np.any((d < radius) & (pts @ direction > 0)))

    def _back_off(
        self, pts: FloatArray, lim: VelocityLimits, holo: bool
    ) -> FloatArray | None:
        """Command ``(3,)`` moving away from the nearest return, or ``None`` if impossible."""
        k = int(np.argmin(np.hypot(pts[:, 0], pts[:, 1])))
        away = -pts[k] / max(float(np.hypot(*pts[k])), 1e-9)
        speed = self._p.backoff_speed
        if holo:
            return np.array([away[0] * speed, away[1] * speed, 0.0])
        if lim.vx_min < 0 and away[0] < 0:
            return np.array([max(lim.vx_min, -speed), 0.0, 0.0])
        return None

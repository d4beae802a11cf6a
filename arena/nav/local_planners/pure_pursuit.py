"""Pure pursuit: steer toward a point one lookahead distance ahead on the global path.

Description:
    Each tick the robot is projected onto the path (the projection only moves forward along a
    given path, so a path that doubles back on itself is followed in order), and the point one
    lookahead distance ``L = lookahead + lookahead_gain · |v|`` further along the path is chased:

    - ``diff_drive`` / ``legged``: the arc through the lookahead point, curvature
      ``κ = 2·y / (x² + y²)`` with ``(x, y)`` the point in the robot frame. If the heading error
      exceeds ``rotate_threshold`` and the robot can turn on the spot (``min_turning_radius == 0``)
      it first rotates in place, until the error falls below half the threshold (hysteresis).
    - ``ackermann``: the same arc with ``|κ| ≤ 1 / min_turning_radius``; no reversing, no turning
      on the spot (a point behind gets the tightest turn toward its side). ``omega = κ · vx``
      exactly, so the turning-radius bound holds every tick (see ``LocalPlanner.compute``).
    - ``omni``: a straight velocity toward the lookahead point, scaled into the ``vx``/``vy``
      box, while ``omega`` turns the heading toward the direction of travel.

Speed profile:
    The forward speed is the smallest of ``max_speed`` (or ``vx_max``), ``omega_max / |κ|``, the
    braking speed ``sqrt(2 · decel · d_goal)`` with ``decel = decel_fraction · acc_x`` (so it
    stops at the goal) and the obstacle speed below; then it is moved at most ``acc · dt`` from
    the current twist. Within ``goal_tolerance`` of the path end the command is zero (braking
    within the acceleration limits).

Obstacle check:
    Laser returns are tested against the corridor the robot sweeps along its direction of motion
    (the arc of curvature ``κ``, or the straight line for omni motion). For each corridor width —
    the robot's own radius, and the radius plus ``safety_margin`` — the free gap ``s`` is the
    distance the disc can move before touching the nearest return ahead. The speed is scaled by
    ``(s - stop_distance) / (slow_distance - stop_distance)`` clipped to ``[0, 1]`` and capped by
    the speed from which the robot can still brake before ``stop_distance``; when the robot's own
    gap is ``≤ stop_distance`` it stops. A return that lies only in the margin band (it would
    pass beside the robot) slows it to ``creep_fraction`` of the speed at most, never to a stop:
    walls of a passage narrower than the margin must not stall the robot.

    If the nominal lookahead's arc is blocked, halved lookaheads down to ``min_lookahead`` are
    tried and the longest one allowing the highest speed is used: a long arc cuts corners, a short
    one follows the (collision-free) path closely. A robot that is blocked anyway and can turn on
    the spot keeps turning toward its lookahead point, so it waits for a pedestrian straight
    ahead but frees itself from a wall it approached at an angle.

Detour:
    A person standing in the way does not leave by itself: a pedestrian whose way leads through
    the robot is held by the robot's repulsion as the robot waits for it, and both wait for good
    (the go1 demo waited ~50 s at 0.47 m from such a person in 4 of 5 episodes). So a robot
    that can turn on the spot and has been blocked for ``detour_after`` seconds steps aside:
    among the straight headings 15°, 30°, … 90° to either side (inside the laser's field of
    view) it takes the one closest to its lookahead point whose corridor is free for
    ``detour_distance`` (ties: away from the nearest return), turns to it, drives that far
    (with the usual obstacle check), then follows the path again. When no side is free (a
    person pressed against the robot beside a wall) a robot that can reverse backs off
    ``detour_distance / 2`` at 0.2 m/s if the corridor behind shows no return (a laser that
    does not look back leaves it unseen: the robot came from there), then tries again. The
    global path is not changed; the stack replans if the detour took the robot more than its
    ``max_path_deviation`` away. Measured on the demo with the go1 (2026-11-27; without the
    detour → with it): the README's 5 episodes 1 → 4 goals; 20 episodes of seed 0 11 → 19 goals
    (46 → 19 contacts); 5 episodes each of seeds 1–4 16 → 18 goals (21 → 22 contacts).

Limitations:
    It never reverses, so a car-like robot that ends up facing a wall stays there; returns are
    not tracked, so a moving pedestrian is treated like a wall at its current position. Later
    local planners (DWA, TEB, MPC) handle both.

Goal heading:
    Optional. With ``align_goal_heading``, or when the navigation stack asks for a goal heading
    (``LocalObservation.goal_yaw_tolerance``, set from the task's ``goal_tolerance_angle``), a
    robot that can turn on the spot rotates to the goal's ``theta`` once within
    ``goal_tolerance`` (to within ``goal_yaw_tolerance``, or half the stack's tolerance if that
    is smaller); otherwise the final heading is whatever the approach left. Ackermann robots
    never align: they cannot turn on the spot, so a heading tolerance is met only by chance.

Arguments:
    See :class:`PurePursuitPlanner.Params`.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.types import wrap_angle_scalar
from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    limit_command,
    stopping_speed,
)
from arena.nav.local_planners.path_tracking import at_goal

# Below this |curvature| (1/m) an arc is treated as a straight line (radius > 1 km).
_STRAIGHT = 1e-3
# m from the detour point at which a detour counts as done.
_DETOUR_REACHED = 0.1
# Share of the cruise speed below which the path counts as blocked (for the detour).
_BLOCKED_SPEED_FRACTION = 0.1
# rad: a detour turns on the spot until its heading error is below this, then drives.
_DETOUR_ALIGN = 0.1
# m/s of a back-off (reversing when no side is free), capped by the robot's reverse limit.
_BACKOFF_SPEED = 0.2


@LOCAL_PLANNERS.register("pure_pursuit", tags=("default", "classic"))
class PurePursuitPlanner:
    """Pure pursuit path follower with a goal-braking speed profile and a laser safety corridor.

    Args:
        params: validated :class:`PurePursuitPlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of :class:`PurePursuitPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        lookahead: float = Field(0.6, gt=0, description="m, lookahead distance at standstill")
        lookahead_gain: float = Field(
            0.5, ge=0, description="s, lookahead grows by this times the current speed"
        )
        max_lookahead: float = Field(1.5, gt=0, description="m, cap on the speed-scaled lookahead")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        rotate_threshold: float = Field(
            0.8, gt=0, le=math.pi,
            description="rad, heading error above which robots that can turn on the spot do so",
        )
        heading_gain: float = Field(
            2.0, gt=0, description="1/s, proportional gain of in-place and omni heading control"
        )
        goal_tolerance: float = Field(
            0.05, gt=0, description="m, distance to the path end at which the planner stops"
        )
        decel_fraction: float = Field(
            0.8, gt=0, le=1,
            description="share of acc_x used for planned braking (headroom for discrete ticks)",
        )
        safety_margin: float = Field(
            0.05, ge=0, description="m, added to the robot radius for the corridor half-width"
        )
        stop_distance: float = Field(
            0.15, ge=0, description="m, free gap to a laser return at which the robot stops"
        )
        slow_distance: float = Field(
            1.0, gt=0, description="m, free gap below which the robot starts slowing down"
        )
        creep_fraction: float = Field(
            0.2, ge=0, le=1,
            description="share of the speed kept when a return lies only in the safety margin",
        )
        min_lookahead: float = Field(
            0.15, gt=0, description="m, shortest lookahead tried when longer arcs are blocked"
        )
        align_goal_heading: bool = Field(
            False, description="turn on the spot to the goal's theta once at the goal"
        )
        goal_yaw_tolerance: float = Field(
            0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
        )
        detour_after: float | None = Field(
            1.0, ge=0,
            description="s blocked before a robot that turns on the spot steps aside; None: never",
        )
        detour_distance: float = Field(
            1.0, gt=0, description="m driven sideways on a detour around a blocking return"
        )

        @model_validator(mode="after")
        def _check(self) -> PurePursuitPlanner.Params:
            if self.slow_distance <= self.stop_distance:
                raise ValueError(
                    f"slow_distance ({self.slow_distance}) must exceed stop_distance "
                    f"({self.stop_distance})"
                )
            if self.min_lookahead > self.lookahead:
                raise ValueError(
                    f"min_lookahead ({self.min_lookahead}) must be <= lookahead ({self.lookahead})"
                )
            if self.max_lookahead < self.lookahead:
                raise ValueError(
                    f"max_lookahead ({self.max_lookahead}) must be >= lookahead ({self.lookahead})"
                )
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path, the progress along it and the rotate-in-place latch."""
        self._path: NDArray[np.float64] | None = None
        self._cum = np.zeros(1)
        self._seg = 0
        self._rotating = False
        self._blocked_since: float | None = None
        self._detour: NDArray[np.float64] | None = None  # (2,) world target of the detour
        self._detour_until = 0.0
        self._backoff: NDArray[np.float64] | None = None  # (2,) world point reversed to
        self._backoff_until = 0.0

    # -- path tracking ----------------------------------------------------------------------------
    def _track(self, path: NDArray[np.float64], xy: NDArray[np.float64]) -> tuple[float, float]:
        """Project ``xy`` on the path; return ``(arc length of the projection, path length)``."""
        if self._path is None or self._path.shape != path.shape or not np.array_equal(
            self._path, path
        ):
            self._path = path.copy()
            seg_len = np.linalg.norm(np.diff(path, axis=0), axis=1)
            self._cum = np.concatenate([[0.0], np.cumsum(seg_len)])
            self._seg = 0
        cum = self._cum
        n_seg = len(path) - 1
        # Search a window ahead of the last projection only: progress never jumps back, and a
        # path passing near itself later is not short-cut.
        horizon = cum[self._seg] + self.params.max_lookahead + 2.0
        i1 = int(np.searchsorted(cum, horizon, side="right"))
        i1 = min(max(i1, self._seg + 1), n_seg)
        a = path[self._seg:i1]
        ab = path[self._seg + 1:i1 + 1] - a
        len2 = np.einsum("ij,ij->i", ab, ab)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("ij,ij->i", xy - a, ab) / len2
        t = np.clip(np.nan_to_num(t, nan=0.0, posinf=0.0, neginf=0.0), 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * ab - xy, axis=1)
        j = int(np.argmin(d))
        self._seg += j
        s = cum[self._seg] + t[j] * math.sqrt(len2[j])
        return float(s), float(cum[-1])

    def _point_at(self, s: float) -> NDArray[np.float64]:
        """Return the path point at arc length ``s`` (clamped to the path)."""
        assert self._path is not None
        cum, path = self._cum, self._path
        if s >= cum[-1]:
            return path[-1].copy()
        i = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(path) - 2))
        seg = cum[i + 1] - cum[i]
        t = 0.0 if seg <= 0 else (s - cum[i]) / seg
        return path[i] + t * (path[i + 1] - path[i])

    # -- obstacle corridor -----------------------------------------------------------------------
    def _free_gaps(
        self, points: NDArray[np.float64], heading: NDArray[np.float64], curvature: float,
        robot_radius: float,
    ) -> tuple[float, float]:
        """Distances (m) the robot can travel along its motion before a return enters its corridor.

        Args:
            points: ``(m, 2)`` laser returns in the robot frame.
            heading: ``(2,)`` unit direction of straight motion in the robot frame (used when
                ``curvature`` is ~0).
            curvature: signed curvature of forward motion (1/m, CCW positive).
            robot_radius: robot radius (m).

        Returns:
            ``(gap of the robot's own disc, gap of the disc grown by safety_margin)``; ``inf``
            when nothing lies ahead in that corridor.
        """
        if len(points) == 0:
            return math.inf, math.inf
        if abs(curvature) < _STRAIGHT:
            along = points @ heading
            lateral = np.abs(points[:, 0] * heading[1] - points[:, 1] * heading[0])
        else:
            # Arc of radius rk about (0, rk): lateral offset from the arc, distance along it.
            rk = 1.0 / curvature
            rel = points - np.array([0.0, rk])
            lateral = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - abs(rk))
            # Angle swept from the robot (at -rk·ŷ from the centre) to the point, in the turn sense.
            r0 = np.array([0.0, -rk])
            cross = r0[0] * rel[:, 1] - r0[1] * rel[:, 0]
            phi = np.arctan2(cross, rel @ r0) * math.copysign(1.0, curvature)
            along = phi * abs(rk)
        # Returns inside the robot's own disc already block it, unless they are behind.
        if np.any((np.hypot(points[:, 0], points[:, 1]) < robot_radius) & (along >= 0)):
            return 0.0, 0.0
        gaps = []
        for half in (robot_radius, robot_radius + self.params.safety_margin):
            ahead = (along > 0) & (lateral < half)
            if not np.any(ahead):
                gaps.append(math.inf)
                continue
            # The disc's front reaches a point at lateral offset l after along - sqrt(half² - l²).
            gap = along[ahead] - np.sqrt(np.maximum(half * half - lateral[ahead] ** 2, 0.0))
            gaps.append(float(max(np.min(gap), 0.0)))
        return gaps[0], gaps[1]

    def _obstacle_speed(self, gaps: tuple[float, float], v_ref: float, decel: float) -> float:
        """Speed (m/s) allowed by the returns ahead, given :meth:`_free_gaps`' two gaps."""
        p = self.params
        gap_robot, gap_margin = gaps
        if gap_robot <= p.stop_distance:
            return 0.0
        span = p.slow_distance - p.stop_distance
        ramp_robot = min((gap_robot - p.stop_distance) / span, 1.0)
        ramp_margin = min(max((gap_margin - p.stop_distance) / span, 0.0), 1.0)
        # A return only inside the margin band (it would not touch the robot itself) slows the
        # robot down to a creep but never stops it: otherwise a wall along a narrow passage,
        # closer than the margin, would stall the robot for good.
        factor = min(ramp_robot, max(ramp_margin, p.creep_fraction))
        return min(v_ref * factor, stopping_speed(gap_robot - p.stop_distance, decel))

    def _lookaheads(self, speed: float) -> list[float]:
        """Lookahead distances to try, longest first: the nominal one, then halved."""
        p = self.params
        look = min(p.lookahead + p.lookahead_gain * speed, p.max_lookahead)
        out = [look]
        while out[-1] > p.min_lookahead:
            out.append(max(out[-1] / 2.0, p.min_lookahead))
        return out

    # -- control ----------------------------------------------------------------------------------
    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self.params
        lim = obs.limits
        dt = float(obs.dt)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        path = np.asarray(obs.path, dtype=np.float64).reshape(-1, 2)
        if len(path) == 0:
            path = obs.goal_pose.xy[None, :]
        if len(path) == 1:
            path = np.vstack([path, path])
        xy = pose[:2]
        theta = float(pose[2])
        drive = obs.drive
        can_spin = lim.min_turning_radius <= 0 and drive != "ackermann"

        s, total = self._track(path, xy)
        end = path[-1]
        d_end = float(np.hypot(*(end - xy)))
        if at_goal(obs, d_end, p.goal_tolerance):
            self._rotating = False
            cmd = np.zeros(3)
            want = obs.goal_yaw_tolerance
            if (p.align_goal_heading or want is not None) and can_spin:
                tol = p.goal_yaw_tolerance if want is None else min(p.goal_yaw_tolerance, want / 2)
                err = wrap_angle_scalar(obs.goal_pose.theta - theta)
                if abs(err) > tol:
                    cmd[2] = p.heading_gain * err
            return limit_command(cmd, twist, lim, dt)

        backing = self._backoff_command(obs)
        if backing is not None:
            return backing

        d_goal = max(total - s, d_end)
        decel = p.decel_fraction * lim.acc_x
        v_ref = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        v_ref = min(v_ref, stopping_speed(d_goal, decel))
        points = obs.scan_points()
        c, sn = math.cos(theta), math.sin(theta)
        omni = drive == "omni"
        k_max = 1.0 / lim.min_turning_radius if lim.min_turning_radius > 0 else math.inf

        # Try the nominal lookahead, then shorter ones: where the long arc (or line) would cut a
        # corner into a laser return, a shorter one follows the collision-free path more closely.
        # Keep the longest lookahead among those that allow the highest speed.
        best: tuple[float, float, float, float, tuple[float, float]] | None = None
        for look in self._lookaheads(float(np.hypot(twist[0], twist[1]))):
            dx, dy = self._point_at(s + look) - xy
            tx, ty = c * dx + sn * dy, -sn * dx + c * dy  # lookahead point in the robot frame
            if tx == 0.0 and ty == 0.0:
                tx = 1e-9  # degenerate: the target is the robot itself
            if omni:
                kappa = 0.0
                heading = np.array([tx, ty]) / math.hypot(tx, ty)
            else:
                kappa = 2.0 * ty / (tx * tx + ty * ty)
                if k_max < math.inf:
                    if tx < 0:  # target behind: tightest turn toward its side (no reversing)
                        kappa = math.copysign(k_max, ty if ty != 0 else 1.0)
                    kappa = float(np.clip(kappa, -k_max, k_max))
                heading = np.array([1.0, 0.0])
            gaps = self._free_gaps(points, heading, kappa, obs.robot_radius)
            allowed = self._obstacle_speed(gaps, v_ref, decel)
            if best is None or allowed > best[0] + 1e-9:
                best = (allowed, tx, ty, kappa, gaps)
            if allowed >= v_ref - 1e-9:
                break  # nothing faster to find
        assert best is not None
        _, tx, ty, kappa, gaps = best
        detour = False
        if can_spin and not omni and p.detour_after is not None:
            target = self._detour_target(obs, points, best, v_ref, decel)
            if target is not None:
                detour = True
                tx, ty = target
                kappa = 2.0 * ty / (tx * tx + ty * ty)
                gaps = self._free_gaps(points, np.array([1.0, 0.0]), kappa, obs.robot_radius)

        if omni:
            return self._omni(obs, twist, (tx, ty), v_ref, decel, gaps)

        alpha = math.atan2(ty, tx)
        if detour:
            # turn on the spot to the detour's heading (its free corridor is straight), then go
            self._rotating = abs(alpha) > _DETOUR_ALIGN
        elif can_spin:
            if abs(alpha) > p.rotate_threshold:
                self._rotating = True
            elif abs(alpha) < 0.5 * p.rotate_threshold:
                self._rotating = False
        else:
            self._rotating = False
        if self._rotating:
            return limit_command(np.array([0.0, 0.0, p.heading_gain * alpha]), twist, lim, dt)

        v_cap = v_ref if kappa == 0 else min(v_ref, lim.omega_max / abs(kappa))
        v_des = self._obstacle_speed(gaps, v_cap, decel)
        v_lo, v_hi = twist[0] - lim.acc_x * dt, twist[0] + lim.acc_x * dt
        v = float(np.clip(np.clip(v_des, v_lo, v_hi), lim.vx_min, lim.vx_max))
        if not can_spin:
            # Car-like: the yaw rate is speed × curvature and follows the speed at once (the real
            # rate limit is the steering rate, which VelocityLimits does not carry), so keep the
            # curvature bound exact instead of rate-limiting omega.
            w = float(np.clip(kappa * v, -lim.omega_max, lim.omega_max))
            return lim.clip(np.array([v, 0.0, w]))
        w_lo, w_hi = twist[2] - lim.acc_omega * dt, twist[2] + lim.acc_omega * dt
        w = float(np.clip(np.clip(kappa * v, w_lo, w_hi), -lim.omega_max, lim.omega_max))
        if abs(kappa) >= _STRAIGHT and abs(w) < abs(kappa * v):
            # The yaw rate lagged: slow down (as far as braking allows) to keep the curvature.
            v = float(np.clip(max(abs(w / kappa), v_lo), lim.vx_min, lim.vx_max))
        if v_des == 0.0 and gaps[0] <= p.stop_distance:
            # Blocked: keep turning toward the path (a return dead ahead leaves alpha ≈ 0: wait).
            w = p.heading_gain * alpha
        return limit_command(np.array([v, 0.0, w]), twist, lim, dt)

    # -- detour ------------------------------------------------------------------------------
    def _detour_target(
        self,
        obs: LocalObservation,
        points: NDArray[np.float64],
        best: tuple[float, float, float, float, tuple[float, float]],
        v_ref: float,
        decel: float,
    ) -> tuple[float, float] | None:
        """The detour point in the robot frame while a detour runs, else ``None``.

        Starts a detour once the path has been blocked for ``detour_after`` s (see the module
        docstring); ends it at its point, at its deadline, or when it is blocked itself.
        """
        p = self.params
        assert p.detour_after is not None
        now = float(obs.time)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        if self._detour is not None:
            dx, dy = self._detour - pose[:2]
            target = (c * dx + sn * dy, -sn * dx + c * dy)
            if math.hypot(dx, dy) > _DETOUR_REACHED and now < self._detour_until:
                if abs(math.atan2(target[1], target[0])) > _DETOUR_ALIGN:
                    return target  # still turning to it: turning on the spot is safe
                k = 2.0 * target[1] / (target[0] ** 2 + target[1] ** 2)
                gaps = self._free_gaps(points, np.array([1.0, 0.0]), k, obs.robot_radius)
                if self._obstacle_speed(gaps, v_ref, decel) >= _BLOCKED_SPEED_FRACTION * v_ref:
                    return target
            self._detour = None  # reached, too late or blocked: back to the path
        allowed, tx, ty, _, gaps = best
        # "Blocked" is hardly moving, not exactly stopped: at the stop distance the gap flickers
        # around it by millimetres, and a creep of 1 cm/s is as stuck as a stop.
        if allowed >= _BLOCKED_SPEED_FRACTION * v_ref:
            self._blocked_since = None
            return None
        if self._blocked_since is None:
            self._blocked_since = now
        if now - self._blocked_since < p.detour_after - 1e-9:
            return None
        delta = self._detour_heading(obs, points, math.atan2(ty, tx))
        if delta is None:
            self._start_backoff(obs, points, pose)
            return None  # no free side: back off if possible, else keep waiting
        self._blocked_since = None
        local = p.detour_distance * np.array([math.cos(delta), math.sin(delta)])
        self._detour = pose[:2] + np.array([c * local[0] - sn * local[1],
                                            sn * local[0] + c * local[1]])
        lim = obs.limits
        # time to turn to it and drive there at a crawl; a detour never runs forever
        self._detour_until = now + abs(delta) / max(lim.omega_max, 1e-3) + 4.0 * (
            p.detour_distance / max(min(v_ref, lim.vx_max), 0.05)
        )
        return float(local[0]), float(local[1])

    def _start_backoff(
        self, obs: LocalObservation, points: NDArray[np.float64], pose: NDArray[np.float64]
    ) -> None:
        """Reverse half a detour distance when no side is free and the corridor behind is."""
        p = self.params
        if obs.limits.vx_min >= 0.0:
            return  # cannot reverse
        back = 0.5 * p.detour_distance
        # beams that do not look back leave the rear unseen: the robot came from there
        gap = self._free_gaps(points, np.array([-1.0, 0.0]), 0.0, obs.robot_radius)[0]
        if gap < back + p.stop_distance:
            return
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        self._blocked_since = None
        self._backoff = pose[:2] - back * np.array([c, sn])
        speed = min(_BACKOFF_SPEED, -obs.limits.vx_min)
        self._backoff_until = float(obs.time) + 3.0 * back / speed

    def _backoff_command(self, obs: LocalObservation) -> NDArray[np.float64] | None:
        """The reversing command while a back-off runs, else ``None`` (it ended)."""
        if self._backoff is None:
            return None
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        if (float(np.hypot(*(self._backoff - pose[:2]))) <= _DETOUR_REACHED
                or float(obs.time) >= self._backoff_until):
            self._backoff = None
            return None
        lim = obs.limits
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        speed = min(_BACKOFF_SPEED, -lim.vx_min)
        return limit_command(np.array([-speed, 0.0, 0.0]), twist, lim, float(obs.dt))

    def _detour_heading(
        self, obs: LocalObservation, points: NDArray[np.float64], preferred: float
    ) -> float | None:
        """Heading (rad, robot frame) of a free straight detour closest to ``preferred``."""
        p = self.params
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        lo, hi = float(np.min(angles)), float(np.max(angles))
        ahead = points[points[:, 0] > 0.0] if len(points) else points
        # ties go away from the nearest return ahead (its side: the sign of its y)
        away = -math.copysign(1.0, float(ahead[np.argmin(np.hypot(*ahead.T)), 1])) if len(
            ahead
        ) else 1.0
        need = p.detour_distance + p.stop_distance
        options = []
        for k in range(1, 7):
            for side in (1.0, -1.0):
                delta = side * k * math.pi / 12.0
                if not lo <= delta <= hi:
                    continue  # unseen directions are not free for certain
                heading = np.array([math.cos(delta), math.sin(delta)])
                gap = self._free_gaps(points, heading, 0.0, obs.robot_radius)[0]
                if gap >= need:
                    options.append((abs(wrap_angle_scalar(delta - preferred)), -side * away, delta))
        return min(options)[2] if options else None

    def _omni(
        self,
        obs: LocalObservation,
        twist: NDArray[np.float64],
        target: tuple[float, float],
        v_ref: float,
        decel: float,
        gaps: tuple[float, float],
    ) -> NDArray[np.float64]:
        """Holonomic motion straight at the lookahead point; heading follows the motion."""
        p = self.params
        lim = obs.limits
        dt = float(obs.dt)
        tx, ty = target
        u = np.array([tx, ty]) / math.hypot(tx, ty)
        # Largest speed along u inside the vx/vy box.
        bounds = []
        for comp, lo, hi in ((u[0], lim.vx_min, lim.vx_max), (u[1], lim.vy_min, lim.vy_max)):
            if comp > 1e-12:
                bounds.append(hi / comp)
            elif comp < -1e-12:
                bounds.append(lo / comp)
        v_box = max(min(bounds), 0.0) if bounds else 0.0
        speed = self._obstacle_speed(gaps, min(v_ref, v_box), decel)
        want = speed * u
        # Scale the velocity change as a whole so acceleration limits keep the direction of change.
        dv = want - twist[:2]
        room = np.array([lim.acc_x, lim.acc_y]) * dt
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.where(np.abs(dv) > 1e-12, room / np.abs(dv), np.inf)
        scale = min(1.0, float(np.min(ratios)))
        vxy = twist[:2] + scale * dv
        # Turning on the spot is always safe for the disc model, and it lets a robot that cannot
        # move backwards (vx_min = 0) face a target behind it.
        w = p.heading_gain * math.atan2(ty, tx)
        return limit_command(np.array([vxy[0], vxy[1], w]), twist, lim, dt)

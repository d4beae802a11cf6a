"""Dragon: a gap-based subgoal in front of the Dynamic Window Approach (BARN challenge style).

Description:
    The gap-based planners that did well at the BARN challenge (DRAGON among them) look at the
    2D lidar for *gaps* — openings between obstacles — and steer a classical controller through
    the one that leads toward the goal. No learning is involved. Each tick:

    1. **Target.** The point ``lookahead`` metres ahead of the robot along the global path (the
       goal when it is closer), tracked forward-only.
    2. **Direct.** When the straight segment from the robot to the target keeps the robot's
       radius from every laser return, the path is followed as it is: the gap search only
       matters where the path disappears behind an obstacle.
    3. **Gaps.** Otherwise the scan's swept gaps (beams without a return within ``max_range``)
       and radial gaps (range jumps larger than ``jump``) are found
       (:func:`~arena.nav.local_planners.gaps.find_gaps`).
    4. **Admissible.** A gap is kept if the robot fits: its width (the distance between its two
       sides) is at least ``2 · robot_radius + margin``. Its subgoal lies just past the gap's
       mouth (``robot_radius + margin / 2`` beyond its nearer side), on the bearing inside the
       gap closest to the target's, kept away from each side by the angle the robot subtends
       there, and short of the return on that bearing. The gap is reachable if the straight
       segment from the robot to that subgoal keeps the robot's radius from every return.
    5. **Choice.** Of the admissible, reachable gaps, the one whose subgoal is nearest the
       target wins. The previous tick's gap is kept while its subgoal is within
       ``switch_margin`` metres of as good (gap methods otherwise flicker between two openings).
    6. **Follow.** The embedded :class:`~arena.nav.local_planners.dwa.DWAPlanner` (its own
       ``dwa`` parameters) follows a path from the robot through the subgoal to the target and
       on along the global path; velocity sampling, safety and goal braking are DWA's. With no
       admissible gap DWA follows the global path itself and its collision checks decide.
    7. **Escape.** Where DWA stops short of the goal because a return ahead is nearer than its
       ``min_clearance`` (every forward arc would shrink the clearance, DWA's local minimum),
       a robot that turns on the spot turns away from that return until it lies abeam.

    The footprint is the robot's bounding circle (``robot_radius``), as for DWA.

Goal:
    As DWA: within its ``goal_tolerance`` of the goal the robot brakes, then aligns to the goal
    heading when the stack asks for one.

Arguments:
    See :class:`DragonPlanner.Params`; ``dwa`` takes :class:`DWAPlanner.Params`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    limit_command,
)
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.gaps import Gaps, find_gaps
from arena.nav.local_planners.path_tracking import PathTracker, to_robot_frame


@dataclass(frozen=True)
class GapChoice:
    """What :meth:`DragonPlanner.choose` decided at one tick (robot frame, metres).

    Attributes:
        target: ``(2,)`` the global-path lookahead point.
        direct: True when the target was in sight (no gap needed; the rest is empty).
        gaps: the scan's gaps (``n``).
        admissible: ``(n,)`` bool, the robot fits through the gap and reaches its subgoal.
        subgoals: ``(n, 2)`` each gap's subgoal.
        chosen: index of the chosen gap, or ``None`` (direct, or no admissible gap).
    """

    target: NDArray[np.float64]
    direct: bool
    gaps: Gaps
    admissible: NDArray[np.bool_]
    subgoals: NDArray[np.float64]
    chosen: int | None

    @property
    def subgoal(self) -> NDArray[np.float64] | None:
        """``(2,)`` the chosen gap's subgoal, or ``None``."""
        return None if self.chosen is None else self.subgoals[self.chosen]


def segment_clearance(end: NDArray[np.float64], pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance (m) of ``pts`` ``(m, 2)`` to each segment from the origin to ``end`` ``(k, 2)``.

    Returns:
        ``(k,)`` the smallest distance per segment (``inf`` without points).
    """
    end = np.asarray(end, dtype=np.float64).reshape(-1, 2)
    if len(pts) == 0:
        return np.full(len(end), np.inf)
    len2 = np.maximum(np.einsum("kj,kj->k", end, end), 1e-18)
    t = np.clip(pts @ end.T / len2, 0.0, 1.0)  # (m, k)
    dx = pts[:, 0:1] - t * end[:, 0]
    dy = pts[:, 1:2] - t * end[:, 1]
    return np.asarray(np.sqrt(np.min(dx * dx + dy * dy, axis=0)), dtype=np.float64)


@LOCAL_PLANNERS.register("dragon", tags=("classic", "gap", "barn"))
class DragonPlanner:
    """Gap-based local planner: the lidar gap toward the goal as a subgoal, followed by DWA.

    Args:
        params: validated :class:`DragonPlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of :class:`DragonPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        max_range: float = Field(
            3.0, gt=0, description="m, gap horizon: returns at least this far count as open"
        )
        jump: float = Field(
            0.5, gt=0, description="m, range jump between neighbouring beams making a radial gap"
        )
        margin: float = Field(
            0.1, ge=0, description="m added to the robot's diameter for a gap to be admissible"
        )
        lookahead: float = Field(
            2.0, gt=0, description="m along the global path to the target the gaps aim at"
        )
        switch_margin: float = Field(
            0.3, ge=0, description="m, a new gap must bring the subgoal this much nearer the "
            "target to replace the previous tick's",
        )
        hold_radius: float = Field(
            0.5, gt=0, description="m, a gap whose subgoal lies this close to the previous "
            "subgoal counts as the previous tick's gap",
        )
        dwa: DWAPlanner.Params = Field(
            default_factory=lambda: DWAPlanner.Params(min_clearance=0.0),
            description="the DWA that follows the subgoal; min_clearance 0 (DWA's collision "
            "and braking checks stay): the subgoals keep the robot off the sides, and DWA's "
            "0.05 m rule stalls it in the narrow passages of barn maps",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._dwa = DWAPlanner(self.params.dwa)
        self._tracker = PathTracker()
        self.reset()

    def reset(self) -> None:
        """Forget the path progress, the previous gap and DWA's state."""
        self._tracker.reset()
        self._dwa.reset()
        self._last: NDArray[np.float64] | None = None  # previous subgoal, world frame
        self._target_s = 0.0  # arc length (m) of this tick's target along the global path
        self.last_choice: GapChoice | None = None

    # -- gap choice -------------------------------------------------------------------------------
    def _subgoals(
        self, gaps: Gaps, target: NDArray[np.float64], ranges: NDArray[np.float64],
        angles: NDArray[np.float64], radius: float,
    ) -> NDArray[np.float64]:
        """``(n, 2)`` subgoal per gap (robot frame; see the module docstring, step 4)."""
        p = self.params
        rho = radius + 0.5 * p.margin
        o = gaps.origin
        # bearing of the target from the sensor, unwrapped into [right, right + 2π)
        t_bearing = math.atan2(target[1] - o[1], target[0] - o[0])
        rel = np.mod(t_bearing - gaps.right_angle, 2.0 * math.pi)
        phi_t = gaps.right_angle + rel
        a_r = np.arcsin(np.minimum(1.0, rho / np.maximum(gaps.right_range, 1e-9)))
        a_l = np.arcsin(np.minimum(1.0, rho / np.maximum(gaps.left_range, 1e-9)))
        lo, hi = gaps.right_angle + a_r, gaps.left_angle - a_l
        # past the left side: whichever end of the interval is angularly nearer
        past = phi_t > hi
        to_lo = gaps.right_angle + 2.0 * math.pi - phi_t
        phi = np.where(past, np.where(phi_t - hi <= to_lo, hi, lo), np.maximum(phi_t, lo))
        mid = np.arctan2(*(gaps.right_points + gaps.left_points - 2.0 * o).T[::-1])
        phi = np.where(lo > hi, mid, phi)  # a gap too narrow to keep off both sides: its middle
        # distance: just past the mouth, short of the return on the bearing itself
        r_open = np.where(np.isfinite(ranges) & (ranges > 0), np.minimum(ranges, p.max_range),
                          p.max_range)
        wrapped = np.angle(np.exp(1j * phi))
        diff = np.abs(np.angle(np.exp(1j * (wrapped[:, None] - angles[None, :]))))
        beam = np.argmin(diff, axis=1)
        d = np.minimum(np.minimum(gaps.right_range, gaps.left_range) + rho, r_open[beam] - rho)
        d = np.clip(d, 0.0, p.max_range)
        return np.stack([o[0] + d * np.cos(phi), o[1] + d * np.sin(phi)], axis=-1)

    def choose(self, obs: LocalObservation) -> GapChoice:
        """Decide this tick's target, gaps and subgoal (robot frame); see the module docstring.

        Updates the forward-only path progress and the previous-gap memory.
        """
        p = self.params
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        path = self._path(obs)
        s = self._tracker.track(path, pose[:2])
        self._target_s = min(s + p.lookahead, self._tracker.total)
        target_w = self._tracker.point_at(self._target_s)
        target = to_robot_frame(target_w, pose)
        pts = obs.scan_points()
        radius = float(obs.robot_radius)
        none = np.zeros(0, dtype=bool)
        if float(segment_clearance(target, pts)[0]) >= radius:
            self._last = None
            return GapChoice(target, True, Gaps.empty(), none, np.zeros((0, 2)), None)
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        gaps = find_gaps(ranges, angles, max_range=p.max_range, jump=p.jump,
                         origin=np.asarray(obs.scan_origin, dtype=np.float64))
        if len(gaps) == 0:
            self._last = None
            return GapChoice(target, False, gaps, none, np.zeros((0, 2)), None)
        subgoals = self._subgoals(gaps, target, ranges, angles, radius)
        fits = gaps.width >= 2.0 * radius + p.margin
        reach = segment_clearance(subgoals, pts) >= radius
        moves = np.hypot(subgoals[:, 0], subgoals[:, 1]) > 1e-3
        ok = fits & reach & moves
        chosen: int | None = None
        if ok.any():
            cost = np.where(ok, np.hypot(*(subgoals - target).T), np.inf)
            chosen = int(np.argmin(cost))
            if self._last is not None:
                # keep the previous gap while it stays nearly as good (no flicker)
                prev = to_robot_frame(self._last, pose)
                held = ok & (np.hypot(*(subgoals - prev).T) <= p.hold_radius)
                if held.any():
                    k = int(np.argmin(np.where(held, cost, np.inf)))
                    if cost[k] <= cost[chosen] + p.switch_margin:
                        chosen = k
        if chosen is None:
            self._last = None
        else:
            c, sn = math.cos(pose[2]), math.sin(pose[2])
            g = subgoals[chosen]
            self._last = pose[:2] + np.array([c * g[0] - sn * g[1], sn * g[0] + c * g[1]])
        return GapChoice(target, False, gaps, ok, subgoals, chosen)

    # -- control ----------------------------------------------------------------------------------
    def _path(self, obs: LocalObservation) -> NDArray[np.float64]:
        path = PathTracker.normalise(obs.path, obs.goal_pose.xy)
        goal_xy = obs.goal_pose.xy
        if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
            path = np.vstack([path, goal_xy])  # as DWA: the path may end near, not on, the goal
        return path

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        choice = self.choose(obs)
        self.last_choice = choice
        if self._last is None:
            return self._escape(obs, self._dwa.compute(obs))
        # the path DWA follows: robot -> subgoal -> target -> rest of the global path
        tr = self._tracker
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        target_w = tr.point_at(self._target_s)
        rest = tr.path[tr.cum > self._target_s + 1e-9]
        detour = np.vstack([pose[:2], self._last, target_w, rest])
        return self._escape(obs, self._dwa.compute(replace(obs, path=detour)))

    def _escape(self, obs: LocalObservation, cmd: NDArray[np.float64]) -> NDArray[np.float64]:
        """Turn away from a return DWA will not drive past (its local minimum), else ``cmd``.

        DWA keeps its ``min_clearance`` and, once closer, refuses every motion that shrinks the
        clearance: with a return ahead within it, every forward arc does, and a robot facing its
        goal stops for good. Turning on the spot (always free for the bounding circle) until
        that return lies abeam lets DWA move again. Robots that cannot turn on the spot and
        holonomic ones (DWA samples sideways motion) keep DWA's command.
        """
        lim = obs.limits
        if np.any(np.abs(cmd) > 1e-9) or lim.min_turning_radius > 0 or lim.holonomic:
            return cmd
        pts = obs.scan_points()
        if len(pts) == 0:
            return cmd
        d = np.hypot(pts[:, 0], pts[:, 1])
        k = int(np.argmin(d))
        bearing = math.atan2(pts[k, 1], pts[k, 0])
        if d[k] - obs.robot_radius >= self.params.dwa.min_clearance or abs(bearing) >= math.pi / 2:
            return cmd
        goal_r = to_robot_frame(obs.goal_pose.xy, np.asarray(obs.pose, dtype=np.float64))
        if float(np.hypot(*goal_r)) <= self.params.dwa.goal_tolerance:
            return cmd  # arrived: DWA's stop (or alignment) stands
        turn = np.array([0.0, 0.0, -math.copysign(lim.omega_max, bearing)])
        return limit_command(turn, np.asarray(obs.twist, dtype=np.float64), lim, float(obs.dt))

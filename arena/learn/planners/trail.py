"""``trail``: DRL-VO's PPO policy with TRAIL's rotate-in-place rule (BARN Challenge 2022).

Description:
    TRAIL, the Temple University entry that took third place at the BARN Challenge 2022 (Xiao
    et al., "Autonomous Ground Navigation in Highly Constrained Spaces: Lessons learned from the
    BARN Challenge at ICRA 2022"), deployed DRL-VO (Xie & Dames, "DRL-VO: Learning to Navigate
    Through Crowded Dynamic Scenes Using Velocity Obstacles", T-RO 2023): a PPO policy whose
    network reads the recent laser scans, min- and average-pooled, a pedestrian kinematic map
    (the people's velocities on an ego-centric grid) and a subgoal on the global path, and
    outputs ``[v, ω]``; in front of obstacles the robot turns in place toward the subgoal
    before the policy drives on.

    Here: the network is :class:`~arena.learn.extractors.DrlvoExtractor` (two conv branches,
    scans and map, then an MLP), run with numpy (:class:`~arena.learn.policy.NumpyPolicy`); the
    observation is rebuilt each tick by :class:`~arena.learn.planners.learned.PolicyPlanner`
    (``lidar``: the last scans resampled onto the policy's beams; ``semantic``: the known
    people of the observation on the policy's grid; ``goal``: a subgoal on the global path;
    ``last_action``). The packaged weights (``arena/learn/data/policies/trail.npz``) were
    trained here (behaviour cloning of a velocity-obstacle gap follower on generated barn and
    indoor maps with people, then PPO; docs/learning.md, "trail").

    The rotate-in-place rule (ours, from the description of TRAIL's deployment): when the
    subgoal lies more than ``rotate_angle`` off the heading, or an obstacle is nearer than
    ``rotate_clearance`` within ``front_sector`` of straight ahead while the subgoal is more
    than ``align_angle`` off, the robot stops translating and turns toward the subgoal at up
    to ``rotate_speed``; the policy drives again once the subgoal is within ``align_angle``.
    Robots that cannot turn on the spot (car-like) skip the rule.

    Stalls (ours): the cloned and fine-tuned policy stops in front of passages it judges too
    narrow, although the global path runs through them (most of its timeouts on the barn suite
    without this). When the robot has not moved ``stall_distance`` within ``stall_time``
    (:class:`~arena.nav.recovery.OscillationMonitor`, the stack's stuck test), DWA drives for
    ``fallback_time`` (the registered ``dwa`` planner, as BRNE's ``alone``), then the policy
    again. ``stall_time: 0`` disables it.

Arguments:
    See :class:`TrailPlanner.Params`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from arena.learn.paths import subgoal_on_path
from arena.learn.planners.learned import PolicyParams, PolicyPlanner
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.path_tracking import finish_command
from arena.nav.recovery import OscillationMonitor

TRAIL_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "trail.npz"
"""The packaged policy (``arena/learn/data/policies/trail.npz``)."""


@LOCAL_PLANNERS.register("trail", tags=("learned",))
class TrailPlanner(PolicyPlanner):
    """DRL-VO's CNN policy (pooled scans, pedestrian map, subgoal) plus turning in place."""

    planner_name: ClassVar[str] = "trail"
    default_weights: ClassVar[Path] = TRAIL_WEIGHTS
    supported_keys: ClassVar[frozenset[str]] = frozenset(
        {"lidar", "goal", "last_action", "semantic"}
    )

    class Params(PolicyParams):
        """Parameters of ``trail``."""

        rotate_angle: float = Field(
            1.2, gt=0, le=math.pi, description="rad; a subgoal farther off the heading: turn"
        )
        rotate_clearance: float = Field(
            0.25, ge=0, description="m beyond the robot's radius; an obstacle this near ahead "
            "and a subgoal off the heading: turn"
        )
        front_sector: float = Field(
            0.5, gt=0, le=math.pi, description="rad either side of straight ahead"
        )
        align_angle: float = Field(
            0.35, gt=0, le=math.pi, description="rad; turning stops within this of the subgoal"
        )
        rotate_speed: float = Field(
            1.0, gt=0, description="rad/s, capped by the robot's own limit"
        )
        stall_time: float = Field(
            3.0, ge=0, description="s without stall_distance of motion before DWA takes over; "
            "0: never"
        )
        stall_distance: float = Field(0.1, gt=0, description="m of motion that is progress")
        fallback_time: float = Field(3.0, gt=0, description="s DWA drives after a stall")

    params: Params

    def __init__(self, params: Params | None = None) -> None:
        p = params if params is not None else self.Params()
        self._stall = OscillationMonitor(p.stall_time, p.stall_distance)
        self._fallback = DWAPlanner()
        super().__init__(p)

    def reset(self) -> None:
        """Forget the scan history, the last command, any turn in progress and any stall."""
        super().reset()
        self._turning = False
        self._fallback.reset()
        self._fallback_until = -math.inf
        self._watch_started = False

    def stalled(self, obs: LocalObservation) -> bool:
        """Whether DWA drives this tick (a stall was detected less than fallback_time ago)."""
        t = float(obs.time)
        if not self._watch_started or t < self._fallback_until - self.params.fallback_time:
            self._stall.reset(obs.pose[:2], t)  # first tick, or the clock went backwards
            self._watch_started = True
        if t < self._fallback_until:
            return True
        if self._stall.update(obs.pose[:2], t):
            self._fallback_until = t + self.params.fallback_time
            self._stall.reset(obs.pose[:2], self._fallback_until)
            self._fallback.reset()
            return True
        return False

    def _subgoal_bearing(self, obs: LocalObservation) -> float:
        """Bearing (rad, robot frame) of the subgoal the policy's goal observation refers to."""
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        target = np.array([obs.goal_pose.x, obs.goal_pose.y])
        path = np.asarray(obs.path, dtype=np.float64).reshape(-1, 2)
        if self.horizon is not None and len(path):
            target = subgoal_on_path(path, pose[:2], self.horizon)
        d = target - pose[:2]
        return float((math.atan2(d[1], d[0]) - pose[2] + math.pi) % (2 * math.pi) - math.pi)

    def _front_clearance(self, obs: LocalObservation) -> float:
        """Distance (m) from the robot's bounding circle to the nearest return ahead."""
        pts = obs.scan_points()  # (k, 2) robot frame
        if pts.size == 0:
            return math.inf
        ahead = np.abs(np.arctan2(pts[:, 1], pts[:, 0])) <= self.params.front_sector
        if not ahead.any():
            return math.inf
        return float(np.hypot(pts[ahead, 0], pts[ahead, 1]).min()) - float(obs.robot_radius)

    def should_turn(self, obs: LocalObservation) -> tuple[bool, float]:
        """Whether the rotate-in-place rule holds this tick, and the subgoal's bearing (rad)."""
        p = self.params
        bearing = self._subgoal_bearing(obs)
        off = abs(bearing)
        if self._turning:
            self._turning = off > p.align_angle
        else:
            blocked = self._front_clearance(obs) < p.rotate_clearance
            self._turning = off > p.rotate_angle or (blocked and off > p.align_angle)
        return self._turning, bearing

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The policy's command, or a turn in place toward the subgoal (see the module doc)."""
        lim = obs.limits
        car = obs.drive == "ackermann" or lim.min_turning_radius > 0
        # the observation is rebuilt every tick so the scan history stays continuous
        policy_obs = self.observation(obs)
        if self.stalled(obs):
            out = self._fallback.compute(obs)
            self._last = np.asarray(out, dtype=np.float64).copy()
            return out
        turn, bearing = (False, 0.0) if car else self.should_turn(obs)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        if turn:
            self._stall.reset(obs.pose[:2], float(obs.time))  # turning toward the path is progress
            omega = min(self.params.rotate_speed, lim.omega_max)
            cmd = np.array([0.0, 0.0, math.copysign(omega, bearing)])
        else:
            cmd = self.policy.command(self.policy.act(policy_obs))
        out = finish_command(cmd, twist, lim, float(obs.dt), car)
        self._last = out.copy()
        return out

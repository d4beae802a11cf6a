"""``lflh``: an MLP trained on hallucinated obstacles, behind a run-time safety check.

Description:
    "From Agile Ground to Aerial Navigation: Learning from Learned Hallucination" (Wang, Xiao,
    Liu, Warnell, Stone; IROS 2021), after "Learning from Hallucination" (Xiao et al.): motions
    driven in open space are labelled with the most constrained obstacles in which they stay
    optimal and collision-free, and a policy learns the command from the scan those obstacles
    would give and the motion's end. Our training data (:mod:`arena.learn.lflh`) *computes*
    the obstacles (walls at a random, speed-dependent clearance just outside the swept disc,
    with gaps) instead of learning a generative model of them; see docs/learning.md, "lflh".

    Every cycle the policy maps the scan (min-pooled into sectors, clipped at 3 m) and the
    direction to the global path's point ``lookahead`` m ahead of the robot's projection to
    ``[v, ω]``. The safety check (:mod:`arena.learn.lflh.safety`) rolls that command out
    against the scan; an unsafe one is replaced by the best safe sampled command, or a turn on
    the spot toward the target when none moves safely. Near the path's end the speed is capped
    so the robot can brake there; at the goal it brakes (and turns to the goal heading when
    asked).

    Sober deployment (Xiao et al., "Agile Robot Navigation through Hallucinated Learning and
    Sober Deployment", ICRA 2021): the policy only saw constrained spaces (hallucinated walls
    beside every motion), so where the space is open it is out of its training distribution
    (in open rooms it crept: 10 % on indoor_people). With ``open_space: dwa`` (default), a
    cycle whose scan has no return within ``open_clearance`` m of the robot's body in the half
    ahead (±90°) is driven by DWA, the registered ``dwa`` planner; ``open_space: policy`` lets
    the policy drive everywhere.

    Inference is numpy alone (:class:`~arena.learn.lflh.actor.LflhActor`). Without a policy
    file the planner fails with a one-line error.

Arguments:
    See :class:`LflhPlanner.Params`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.learn.lflh.actor import LflhActor
from arena.learn.lflh.features import policy_input
from arena.learn.lflh.safety import SafetyParams, safe_command
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation, stopping_speed
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    at_goal,
    finish_command,
    goal_command,
    to_robot_frame,
)

LFLH_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "lflh.npz"
"""The packaged policy (``arena/learn/data/policies/lflh.npz``)."""


@LOCAL_PLANNERS.register("lflh", tags=("learned",))
class LflhPlanner:
    """LfLH's MLP on the scan and the path's lookahead point, with a safety fallback."""

    # it turns on the spot (fallback) and drives [v, ω]: no car-like robots
    supports: ClassVar[frozenset[str]] = frozenset({"diff_drive", "omni", "legged"})

    class Params(BaseModel):
        """Parameters of ``lflh``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        weights: str | None = Field(
            None, description="LfLH policy file (.npz, RUN/policy.npz); None: the packaged one"
        )
        lookahead: float = Field(1.0, gt=0, description="m along the path to the target point")
        goal_tolerance: float = Field(0.1, gt=0, description="m to the path end to brake at")
        yaw_tolerance: float = Field(0.1, gt=0, description="rad, heading error at the goal")
        heading_gain: float = Field(2.0, gt=0, description="1/s, goal-alignment yaw rate per rad")
        safety: SafetyParams = Field(default_factory=SafetyParams)
        open_space: Literal["dwa", "policy"] = Field(
            "dwa", description="who drives where nothing is within open_clearance ahead: DWA "
            "(sober deployment) or the policy")
        open_clearance: float = Field(
            1.0, gt=0, description="m from the body; no return this near ahead: open space")

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params if params is not None else self.Params()
        self.actor = LflhActor.load(p.weights if p.weights is not None else LFLH_WEIGHTS)
        spec = self.actor.laser
        self._angles = np.linspace(spec.angle_min, spec.angle_max, spec.num_beams)
        self._index_key: bytes | None = None
        self._index = np.zeros(0, dtype=np.intp)
        self._valid = np.zeros(0, dtype=bool)
        self.tracker = PathTracker()
        self._open = DWAPlanner() if p.open_space == "dwa" else None
        self.last_source = "policy"
        """What produced the last command: ``policy``, ``fallback``, ``turn``, ``goal`` or
        ``open`` (DWA in open space)."""

    def reset(self) -> None:
        """Forget the path progress."""
        self.tracker.reset()
        if self._open is not None:
            self._open.reset()
        self.last_source = "policy"

    def is_open(self, obs: LocalObservation) -> bool:
        """Whether no scan return lies within ``open_clearance`` of the body in the half ahead."""
        pts = obs.scan_points()
        ahead = pts[pts[:, 0] >= 0.0] if pts.size else pts
        if ahead.size == 0:
            return True
        nearest = float(np.hypot(ahead[:, 0], ahead[:, 1]).min()) - float(obs.robot_radius)
        return nearest > self.params.open_clearance

    def _resample(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The scan at the training beams' angles (nearest beam; none outside the FOV)."""
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        if ranges.size == 0 or ranges.shape != angles.shape:
            return np.full(self._angles.size, np.inf)
        key = angles.tobytes()
        if key != self._index_key:  # the same lidar every cycle: compute the map once
            order = np.argsort(angles)
            pos = np.clip(np.searchsorted(angles[order], self._angles), 1, angles.size - 1)
            lo, hi = order[pos - 1], order[pos]
            near = np.where(np.abs(angles[lo] - self._angles) <= np.abs(angles[hi] - self._angles),
                            lo, hi)
            step = (np.ptp(angles) / max(angles.size - 1, 1)) if angles.size > 1 else math.pi
            self._index = near
            self._valid = np.abs(angles[near] - self._angles) <= step + 1e-9
            self._index_key = key
        return np.where(self._valid, ranges[self._index], np.inf)

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The policy's command for the lookahead point, made safe (module docstring)."""
        p, lim = self.params, obs.limits
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        goal = obs.goal_pose
        path = PathTracker.normalise(obs.path, np.array([goal.x, goal.y]))
        s = self.tracker.track(path, pose[:2])
        d_end = max(self.tracker.total - s, float(np.hypot(*(path[-1] - pose[:2]))))
        if at_goal(obs, d_end, p.goal_tolerance):
            self.last_source = "goal"
            return goal_command(obs, p.heading_gain, p.yaw_tolerance)
        if self._open is not None and self.is_open(obs):
            self.last_source = "open"
            return self._open.compute(obs)
        target = to_robot_frame(self.tracker.point_at(s + p.lookahead)[None], pose)[0]
        raw = self.actor.act(policy_input(self._resample(obs), target, self.actor.features))
        v_cap = min(lim.vx_max, stopping_speed(d_end, lim.acc_x))
        cmd = np.array([np.clip(raw[0], 0.0, v_cap), np.clip(raw[1], -lim.omega_max,
                                                             lim.omega_max)])
        cmd, self.last_source = safe_command(
            cmd, target, obs.scan_points(), float(obs.robot_radius), max(v_cap, 1e-3),
            lim.omega_max, p.safety)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        return finish_command(np.array([cmd[0], 0.0, cmd[1]]), twist, lim, float(obs.dt), False)

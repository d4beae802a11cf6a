"""BRNE: Bayes-rule Nash equilibrium crowd navigation (Sun, Baldini, Hughes, Trautman & Murphey).

Description:
    "Mixed strategy Nash equilibrium for crowd navigation" (IJRR 2024, arXiv 2403.01537) plays
    navigation as a game between the robot and the people near it. Each agent's mixed strategy
    is a distribution over its possible trajectories, represented by weighted samples; the
    equilibrium is found by iterated Bayes-rule updates of the weights. Here, every control tick:

    1. **Agents.** The robot and the ``max_people`` pedestrians nearest to it within
       ``activate_radius`` (from :attr:`LocalObservation.pedestrians`, ``[x, y, vx, vy]``).
       With nobody there the robot follows its nominal trajectory (the path follower below).
    2. **Nominal trajectories** over ``steps`` times up to ``horizon`` (s): the robot moves along
       the global path at cruise speed (braking to stop at the goal), starting where it stands
       with its current velocity and rejoining the path over ``rejoin_time`` (see
       :meth:`BrnePlanner.nominal`); each person keeps the velocity it was observed with.
    3. **Samples.** Each agent's nominal plus ``samples`` Gaussian-process perturbations (RBF
       kernel over time, ``length_scale`` s, ``sample_std`` m, conditioned on zero at ``t = 0``
       so every sample starts at the agent; people's perturbations scaled by
       ``ped_sample_scale``). The perturbations are drawn once, when the planner is built, from
       a generator seeded by ``seed``, and reused every tick (deterministic commands); the first
       sample of each agent is the unperturbed nominal.
    4. **Static obstacles.** Robot samples that pass within ``robot_radius + obstacle_margin``
       of a laser return (downsampled to ``obstacle_cell``) get prior weight 0, as the authors
       mask samples leaving the corridor; if none is left, those with the largest clearance
       are kept.
    5. **Costs.** For every pair of samples of two different agents, a quadratic hinge on their
       closest approach over the horizon (:func:`~.brne_kernels.pair_costs`: ``cost_weight``
       at contact, zero ``cost_reach`` m beyond it).
    6. **Bayes-rule Nash iteration** (:func:`~.brne_kernels.nash_weights`): ``iterations``
       sweeps; each agent's weights become its prior times ``exp(-expected cost)`` against the
       others' current weighted samples, normalised. ``warm_start`` of the robot's prior is its
       previous tick's weights (the samples are the same), so it keeps to the side it chose.
    7. **Plan and command.** The robot's plan is the weighted mean of its samples (its likeliest
       sample if that mean runs into a laser return). The robot heads for the plan's point
       ``track_time`` s ahead at the braking-profile speed times how much slower than the
       nominal the plan is there, capped at the braking speed to the nearest laser return
       along the way; that velocity becomes a twist for the kinematics
       (:func:`~.social_force.velocity_to_twist`: diff-drive and legged robots steer toward
       it; omni robots, and legged ones that can side-step when ``sidestep`` is on, move along
       it; car-like robots steer within their turning radius).

Simplified versus the paper and the authors' code:
    The robot's samples are Gaussian-process samples around the nominal in position space, as
    in the paper; the authors' ROS node instead rolls out a grid of (v, ω) offsets through
    unicycle dynamics and tracks the plan with an LQR-like tracker — here the plan is tracked
    by the kinematics-aware velocity conversion above. The authors' static-obstacle handling
    is a fixed corridor (``y_min``/``y_max``); here it is the laser scan. The cost is a
    quadratic hinge on the gap instead of the paper's ``2 - 2·sigmoid(a1·d^(2·a2))`` on the
    centre distance (no exponential per sample pair, and deeper overlaps rank worse). The
    expected cost sums over the other agents (the authors' code averages); perturbations are
    drawn once per planner, not per tick; there is no pedestrian tracker or timeout (the stack
    gives positions and velocities).

Goal:
    Within ``goal_tolerance`` of the path end it brakes; robots that can turn on the spot then
    align to the goal heading when the stack asks for one (``goal_yaw_tolerance``).

Arguments:
    See :class:`BrnePlanner.Params`. The defaults are tuned for walking robots (the paper's
    Unitree Go1 and Arena's go1/laikago presets: 0.5–0.8 m/s, a 3 s horizon covering a few
    metres); faster robots may want a longer ``activate_radius``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field

from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    stopping_speed,
)
from arena.nav.local_planners.brne_kernels import (
    gp_cholesky,
    gp_perturbations,
    nash_weights,
    pair_costs,
    sample_clearance,
)
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    TrackingParams,
    at_goal,
    goal_command,
)
from arena.nav.local_planners.social_force import cap_by_returns, velocity_to_twist

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class BrneSolution:
    """One tick's game: who played, with which samples and weights, and the robot's plan.

    Attributes:
        times: ``(T,)`` sample times (s) after now.
        people: ``(k,)`` indices into :attr:`LocalObservation.pedestrians` of the people in the
            game, nearest first (agents ``1 … k``).
        samples: ``(1 + k, M, T, 2)`` sampled trajectories (m, world frame); agent 0 is the robot,
            sample 0 of each agent its nominal.
        prior: ``(1 + k, M)`` prior weights (the robot's are 0 for samples that hit obstacles).
        costs: ``(1 + k, M, 1 + k, M)`` pairwise collision costs of the samples.
        weights: ``(1 + k, M)`` equilibrium weights, each row non-negative and summing to 1.
        plan: ``(T, 2)`` the robot's plan, the weighted mean of its samples (m, world frame).
    """

    times: FloatArray
    people: NDArray[np.int64]
    samples: FloatArray
    prior: FloatArray
    costs: NDArray[np.float32]
    weights: FloatArray
    plan: FloatArray


@LOCAL_PLANNERS.register("brne", tags=("game-theoretic", "social"))
class BrnePlanner:
    """Bayes-rule Nash equilibrium crowd navigation (Sun et al. 2024); see the module docstring.

    Args:
        params: validated :class:`BrnePlanner.Params` (defaults if omitted).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(TrackingParams):
        """Parameters of :class:`BrnePlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        samples: int = Field(100, ge=2, description="trajectory samples per agent")
        horizon: float = Field(3.0, gt=0, description="s, planning horizon")
        steps: int = Field(20, ge=2, description="time steps over the horizon")
        iterations: int = Field(10, ge=1, description="Bayes-rule sweeps over the agents")
        max_people: int = Field(10, ge=0, description="nearest pedestrians in the game")
        activate_radius: float = Field(
            5.0, gt=0, description="m, pedestrians farther from the robot are ignored"
        )
        pedestrian_radius: float = Field(0.3, ge=0, description="m, radius of a pedestrian")
        length_scale: float = Field(
            1.6, gt=0, description="s, RBF length scale (larger: straighter samples)"
        )
        sample_std: float = Field(
            0.6, gt=0, description="m, std of the robot's perturbations far from now"
        )
        ped_sample_scale: float = Field(
            0.3, ge=0,
            description="people's perturbations relative to the robot's (how much they yield)",
        )
        cost_weight: float = Field(20.0, gt=0, description="collision cost at contact")
        cost_reach: float = Field(
            0.5, gt=0, description="m, clearance beyond contact at which the cost is zero"
        )
        obstacle_margin: float = Field(
            0.05, ge=0, description="m, robot samples closer than radius + this to a return drop"
        )
        obstacle_cell: float = Field(
            0.1, gt=0, description="m, laser returns are thinned to one per cell of this size"
        )
        max_speed: float | None = Field(
            None, gt=0, description="m/s, cruise speed; None uses the robot's vx_max"
        )
        rejoin_time: float = Field(
            2.0, gt=0, description="s, the nominal returns from the robot's offset to the path"
        )
        track_time: float = Field(
            0.9, gt=0, description="s ahead on the plan of the point the robot heads for"
        )
        warm_start: float = Field(
            0.5, ge=0, lt=1,
            description="share of the robot's prior taken from its previous tick's weights",
        )
        sidestep: bool = Field(
            True, description="legged robots that can side-step follow the plan holonomically"
        )
        seed: int = Field(0, ge=0, description="seed of the Gaussian-process samples")
        alone: Literal["dwa", "tracker"] = Field(
            "dwa", description="who drives while nobody is in the game: DWA (static obstacles "
            "in clutter) or BRNE's own path tracker")

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params if params is not None else self.Params()
        self.times = np.arange(1, p.steps + 1, dtype=np.float64) * (p.horizon / p.steps)
        rng = np.random.default_rng(p.seed)
        unit = gp_cholesky(self.times, p.length_scale, 1.0)
        pert = gp_perturbations(unit, 1 + p.max_people, p.samples, rng) * p.sample_std
        pert[1:] *= p.ped_sample_scale  # people yield less than the robot is willing to
        self._perturbations = pert  # (1 + max_people, M, T, 2), fixed for the planner's life
        self._tracker = PathTracker()
        # BRNE plays against people; its tracker aims far ahead and cuts corners into clutter
        # (26 % success on the barn suite), so with nobody near DWA drives, as it would alone.
        self._alone = DWAPlanner() if p.alone == "dwa" else None
        self.last: BrneSolution | None = None
        self.reset()

    def reset(self) -> None:
        """Forget the tracked path, the progress along it and the last solution."""
        self._tracker.reset()
        if self._alone is not None:
            self._alone.reset()
        self.last = None
        self._robot_weights: FloatArray | None = None  # (M,) previous equilibrium, robot

    # -- the game ---------------------------------------------------------------------------------
    def track(self, obs: LocalObservation) -> float:
        """Project the robot on the path (goal appended); return the arc length (m) reached."""
        path = PathTracker.normalise(obs.path, obs.goal_pose.xy)
        goal_xy = obs.goal_pose.xy
        if np.hypot(*(path[-1] - goal_xy)) > 1e-6:
            path = np.vstack([path, goal_xy])
        return self._tracker.track(path, np.asarray(obs.pose, dtype=np.float64)[:2])

    def nominal(self, obs: LocalObservation, speed: float) -> FloatArray:
        """The robot's nominal trajectory ``(T, 2)`` (m, world) along the path.

        A carrot moves along the path at ``speed`` (m/s) from the robot's projection (braking
        to stop at the path end); the
        nominal is the carrot plus the robot's offset from it, which decays as a critically
        damped error ``e(t) = (e0 + (ė0 + w·e0)·t)·exp(-w·t)`` with ``w = 3 / rejoin_time``:
        it starts at the robot with the robot's velocity (``ė0`` = robot velocity − carrot
        velocity), so a robot already swerving or heading one way keeps doing so at first, and
        it follows the path's corners instead of cutting them.
        """
        s0 = self.track(obs)
        h = float(self.times[0])
        # The carrot brakes to stop at the path end, as the robot will.
        decel = self.params.decel_fraction * obs.limits.acc_x
        total = self._tracker.total
        arc = np.empty(len(self.times) + 1)
        arc[0] = s0
        for k in range(len(self.times)):
            v = min(speed, stopping_speed(total - arc[k], decel))
            arc[k + 1] = min(arc[k] + v * h, total)
        carrot = self._tracker.point_at(arc)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        vel = np.array([c * twist[0] - s * twist[1], s * twist[0] + c * twist[1]])
        e0 = pose[:2] - carrot[0]
        de0 = vel - (carrot[1] - carrot[0]) / h
        w = 3.0 / self.params.rejoin_time
        t = self.times[:, None]
        err = (e0 + (de0 + w * e0) * t) * np.exp(-w * t)
        return np.asarray(carrot[1:] + err, dtype=np.float64)

    def people_in_game(self, obs: LocalObservation) -> NDArray[np.int64]:
        """Indices of the ``max_people`` people nearest the robot within ``activate_radius``."""
        peds = np.asarray(obs.pedestrians, dtype=np.float64).reshape(-1, 4)
        if len(peds) == 0 or self.params.max_people == 0:
            return np.zeros(0, dtype=np.int64)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        d = np.hypot(peds[:, 0] - pose[0], peds[:, 1] - pose[1])
        near = np.flatnonzero(np.isfinite(d) & np.all(np.isfinite(peds), axis=1)
                              & (d <= self.params.activate_radius))
        order = near[np.argsort(d[near], kind="stable")]
        return order[: self.params.max_people].astype(np.int64)

    def obstacle_points(self, obs: LocalObservation, reach: float) -> FloatArray:
        """``(P, 2)`` laser returns within ``reach`` m (world frame), one per ``obstacle_cell``."""
        pts = obs.scan_points()
        if len(pts) == 0:
            return np.zeros((0, 2))
        pts = pts[np.hypot(pts[:, 0], pts[:, 1]) <= reach]
        cell = self.params.obstacle_cell
        _, first = np.unique(np.floor(pts / cell).astype(np.int64), axis=0, return_index=True)
        pts = pts[np.sort(first)]
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return np.stack([pose[0] + c * pts[:, 0] - s * pts[:, 1],
                         pose[1] + s * pts[:, 0] + c * pts[:, 1]], axis=-1)

    def solve(self, obs: LocalObservation, speed: float) -> BrneSolution:
        """Play the game of this tick with the robot's nominal at ``speed`` (m/s)."""
        p = self.params
        people = self.people_in_game(obs)
        peds = np.asarray(obs.pedestrians, dtype=np.float64).reshape(-1, 4)[people]
        n_a = 1 + len(people)
        nominal = np.empty((n_a, len(self.times), 2))
        nominal[0] = self.nominal(obs, speed)
        nominal[1:] = peds[:, None, :2] + self.times[None, :, None] * peds[:, None, 2:]
        samples = nominal[:, None] + self._perturbations[:n_a]  # (A, M, T, 2)
        xs = np.ascontiguousarray(samples[..., 0].transpose(0, 2, 1))  # (A, T, M)
        ys = np.ascontiguousarray(samples[..., 1].transpose(0, 2, 1))
        prior = np.ones((n_a, p.samples))
        if self._robot_weights is not None and p.warm_start > 0:
            # The perturbations are the same every tick, so sample m now is sample m then: lean
            # toward the last equilibrium rather than re-deciding the side to pass on each tick.
            prior[0] = (1.0 - p.warm_start) + p.warm_start * p.samples * self._robot_weights
        reach = (speed * p.horizon + obs.robot_radius + p.obstacle_margin
                 + 3.0 * p.sample_std + 1.0)
        pts = self.obstacle_points(obs, reach)
        if len(pts):
            clear = sample_clearance(xs[0], ys[0], pts)
            ok = clear >= obs.robot_radius + p.obstacle_margin
            # Nothing free: keep the samples that stay farthest from the returns.
            prior[0] *= ok if np.any(ok) else clear >= clear.max() - 0.05
        radii = np.full(n_a, p.pedestrian_radius)
        radii[0] = obs.robot_radius
        costs, active = pair_costs(xs, ys, radii, p.cost_reach, p.cost_weight)
        weights = nash_weights(costs, active, prior, p.iterations)
        plan = np.einsum("m,mtk->tk", weights[0], samples[0])
        if len(pts):
            # The mean of samples passing an obstacle on both sides runs into it: then follow
            # the likeliest sample instead (it is clear, or as clear as any).
            pc = sample_clearance(plan[:, :1].copy(), plan[:, 1:].copy(), pts)[0]
            if pc < obs.robot_radius + p.obstacle_margin:
                plan = samples[0, int(np.argmax(weights[0]))].copy()
        return BrneSolution(self.times, people, samples, prior, costs, weights, plan)

    # -- the command ------------------------------------------------------------------------------
    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Command ``(3,)`` ``[vx, vy, omega]`` for this tick; see the module docstring."""
        p = self.params
        lim = obs.limits
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        s0 = self.track(obs)
        d_end = float(np.hypot(*(self._tracker.path[-1] - pose[:2])))
        if at_goal(obs, d_end, p.goal_tolerance):
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)
        decel = p.decel_fraction * lim.acc_x
        v_top = min(lim.vx_max, p.max_speed) if p.max_speed is not None else lim.vx_max
        if len(self.people_in_game(obs)):
            self.last = self.solve(obs, v_top)
            self._robot_weights = self.last.weights[0]
            plan, nominal = self.last.plan, self.last.samples[0, 0]
        else:
            self.last = self._robot_weights = None
            if self._alone is not None:
                return self._alone.compute(obs)
            plan = nominal = self.nominal(obs, v_top)
        d_goal = max(self._tracker.total - s0, d_end)
        v_pref = min(v_top, stopping_speed(d_goal, decel))
        tau = p.track_time
        target = _plan_point(plan, self.times, tau) - pose[:2]
        ahead = float(np.hypot(*target))
        along = float(np.hypot(*(_plan_point(nominal, self.times, tau) - pose[:2])))
        # The braking profile is the stack's (v_pref); the game only chooses the direction and
        # how much slower than the nominal to go.
        speed = v_pref * min(1.0, ahead / along) if along > 1e-9 else 0.0
        vel = target * (speed / ahead) if ahead > 1e-9 else np.zeros(2)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        vel = np.array([c * vel[0] + s * vel[1], -s * vel[0] + c * vel[1]])  # robot frame
        vel = cap_by_returns(vel, obs, p.stop_distance, decel)
        drive_obs = obs
        if p.sidestep and obs.drive == "legged" and lim.holonomic and lim.min_turning_radius == 0:
            drive_obs = dataclasses.replace(obs, kinematics="omni")
        return velocity_to_twist(vel, drive_obs, p.heading_gain, p.rotate_threshold,
                                 max(v_top * tau, 0.5))


def _plan_point(plan: FloatArray, times: FloatArray, t: float) -> FloatArray:
    """The point ``(2,)`` of ``plan`` ``(T, 2)`` at time ``t`` (s), linear between samples."""
    x = float(np.interp(t, times, plan[:, 0]))
    y = float(np.interp(t, times, plan[:, 1]))
    return np.array([x, y])

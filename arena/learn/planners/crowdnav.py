"""``crowdnav`` and ``sarl``: CrowdNav's value-network policies, trained here, run with numpy.

Description:
    Chen, Liu, Kreiss & Alahi 2019 ("Crowd-Robot Interaction", ICRA; ``vita-epfl/CrowdNav``).
    Each tick the planner builds the joint state of the robot and the pedestrians the stack
    passes on (``LocalObservation.pedestrians``; each given the crowd's body radius
    ``human_radius``), tries every action of CrowdNav's discrete set for one time step ``Δt``
    (humans moving at constant velocity) and takes the action with the largest
    ``reward + γ^(Δt · v_pref) · V(next joint state)`` (:mod:`arena.learn.value`):

    - ``crowdnav``: CADRL's value, an MLP on each rotated (robot, human) pair, minimum over
      humans (``arena/learn/data/policies/crowdnav.npz``);
    - ``sarl``: SARL's value, self-attention over the pairs
      (``arena/learn/data/policies/sarl.npz``).

    Our adaptation to maps with walls, which CrowdNav ignores, follows SARL* (Li et al. 2019):
    the goal of the joint state is a **local goal** ``subgoal_horizon`` m ahead on the stack's
    global path (:func:`~arena.learn.paths.subgoal_on_path`; the goal itself when closer), and
    the **laser returns** prune actions whose step comes within ``robot radius + wall_margin``
    of one and penalise those within ``wall_soft`` (:func:`~arena.learn.value.lookahead`).

    Kinematics: differential drives and legged robots use the unicycle set (rotations in
    ``±min(π/4, ω_max Δt)``, held as ``[v, 0, r / Δt]``; turning on the spot added); omni robots
    the holonomic set (16 directions in the body frame, ``ω = 0``) when the policy file was
    trained with it (``meta.kinematics == "holonomic"``), else the unicycle set, which they can
    drive as well. The shipped files were trained on a Jackal (unicycle, ``v_pref`` 2 m/s).
    ``v_pref`` is the robot's ``vx_max`` (or ``max_speed``). The chosen twist passes
    :func:`~.path_tracking.finish_command`; within the goal tolerance the planner brakes and
    turns to the goal heading (:func:`~.path_tracking.at_goal`, like the other planners).

Arguments:
    See :class:`CrowdNavPlanner.Params`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.learn.paths import subgoal_on_path
from arena.learn.value.actions import ActionSet, Lookahead, build_action_set, lookahead
from arena.learn.value.network import ValuePolicyFile, load_value_policy
from arena.learn.value.state import JointState, joint_state, rotate
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.path_tracking import at_goal, finish_command, goal_command

FloatArray = NDArray[np.float64]
POLICY_DIR = Path(__file__).resolve().parents[1] / "data" / "policies"
"""Where the packaged policy files live (``arena/learn/data/policies/``)."""
WEIGHTS_KEY = "navigation.local_planner.weights"


class ValuePlannerParams(BaseModel):
    """Parameters of the ``crowdnav`` and ``sarl`` planners."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    weights: str | None = Field(
        None, description="policy file (.npz from arena.learn.value.train); None: the packaged one"
    )
    subgoal_horizon: float | None = Field(
        3.0, gt=0, description="m along the global path to the local goal (SARL*); None: goal"
    )
    human_radius: float = Field(
        0.3, gt=0, description="m, body radius given to each pedestrian (the crowd's agent_radius)"
    )
    human_range: float = Field(6.0, gt=0, description="m, pedestrians farther away are ignored")
    max_humans: int = Field(10, ge=1, description="the nearest pedestrians considered")
    max_speed: float | None = Field(
        None, gt=0, description="m/s, v_pref; None uses the robot's vx_max"
    )
    wall_margin: float = Field(
        0.05, ge=0, description="m, actions passing closer to a laser return are pruned"
    )
    wall_soft: float = Field(
        0.3, ge=0, description="m, actions passing closer to a laser return are penalised"
    )
    wall_factor: float = Field(0.5, ge=0, description="1/s, penalty per m of missing clearance")
    goal_tolerance: float = Field(
        0.05, gt=0, description="m, distance to the goal at which the planner brakes"
    )
    goal_yaw_tolerance: float = Field(
        0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
    )
    heading_gain: float = Field(2.0, gt=0, description="1/s, yaw rate per rad when aligning")


def local_goal(obs: LocalObservation, horizon: float | None) -> FloatArray:
    """``(2,)`` the local goal (m, world): ``horizon`` m along ``obs.path``, else the goal.

    A robot that strayed from the path gets the point ``horizon`` m toward that path point
    instead: the value networks only learnt goals up to the training horizons away, and beyond
    them they extrapolate (in both directions), which once lured a robot away from its goal.
    """
    goal = np.array([obs.goal_pose.x, obs.goal_pose.y])
    path = np.asarray(obs.path, dtype=np.float64).reshape(-1, 2)
    if horizon is None or len(path) == 0:
        return goal
    pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
    target = subgoal_on_path(np.vstack([path, goal[None]]), pose[:2], horizon)
    d = target - pose[:2]
    n = float(np.hypot(d[0], d[1]))
    return pose[:2] + d * (horizon / n) if n > horizon else target


def observe(obs: LocalObservation, params: ValuePlannerParams, v_pref: float,
            horizon: float | str | None = "params") -> JointState:
    """The joint state of ``obs`` toward its local goal (also used to record training data).

    ``horizon`` (m) overrides ``params.subgoal_horizon`` (training records several).
    """
    h = params.subgoal_horizon if isinstance(horizon, str) else horizon
    pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
    tw = np.asarray(obs.twist, dtype=np.float64).reshape(3)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    vel = np.array([c * tw[0] - s * tw[1], s * tw[0] + c * tw[1]])
    return joint_state(pose, vel, float(obs.robot_radius), local_goal(obs, h),
                       v_pref, obs.pedestrians, params.human_radius, params.human_range,
                       params.max_humans)


def world_returns(obs: LocalObservation) -> FloatArray:
    """``(m, 2)`` laser returns in the world frame (m)."""
    pts = obs.scan_points()
    pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.column_stack([pose[0] + c * pts[:, 0] - s * pts[:, 1],
                            pose[1] + s * pts[:, 0] + c * pts[:, 1]])


class ValuePlanner:
    """One-step lookahead on a value network (the shared body of ``crowdnav`` and ``sarl``).

    Args:
        params: validated parameters (defaults if omitted).
        policy: an already loaded policy (training); else ``params.weights`` or the packaged
            file is loaded.

    Attributes:
        epsilon: probability of a uniformly random unpruned action (ε-greedy exploration
            while training; 0 otherwise).
        rng: the generator exploration draws from (``None``: no exploration).
        last: the :class:`~arena.learn.value.Lookahead` of the last decision (``None`` at the
            goal or before the first).
    """

    supports: ClassVar[frozenset[str]] = frozenset({"diff_drive", "omni", "legged"})
    network_kind: ClassVar[str] = ""
    file_name: ClassVar[str] = ""
    Params = ValuePlannerParams

    def __init__(self, params: ValuePlannerParams | None = None, *,
                 policy: ValuePolicyFile | None = None) -> None:
        self.params = p = params or self.Params()
        if policy is None:
            path = Path(p.weights) if p.weights is not None else POLICY_DIR / self.file_name
            policy = load_value_policy(path, where=WEIGHTS_KEY)
            source = str(path)
        else:
            source = "<policy>"
        if policy.network.kind != self.network_kind:
            raise ConfigError(
                f"{source}: holds a {policy.network.kind!r} network; this planner needs "
                f"{self.network_kind!r}", path=WEIGHTS_KEY,
            )
        self.policy = policy
        self.gamma = float(policy.meta["gamma"])
        self.time_step = float(policy.meta["time_step"])
        self.epsilon = 0.0
        self.rng: np.random.Generator | None = None
        self._sets: dict[tuple[float, bool, float], ActionSet] = {}
        self.reset()

    def reset(self) -> None:
        """Forget the last decision (the planner keeps no other state)."""
        self.last: Lookahead | None = None
        self.last_action = -1

    def v_pref(self, obs: LocalObservation) -> float:
        """m/s, the preferred speed for ``obs``' robot."""
        v = obs.limits.vx_max
        return min(v, self.params.max_speed) if self.params.max_speed is not None else v

    def action_set(self, obs: LocalObservation) -> ActionSet:
        """The action set for ``obs``' robot (cached)."""
        # Omni robots can drive unicycle actions too; they use the holonomic set only with a
        # policy trained on it (the value of a state depends on the action model it learnt).
        holo = obs.drive == "omni" and self.policy.meta.get("kinematics") == "holonomic"
        key = (self.v_pref(obs), holo, obs.limits.omega_max)
        if key not in self._sets:
            rot = min(math.pi / 4, obs.limits.omega_max * self.time_step)
            self._sets[key] = build_action_set(key[0], holo, self.time_step, max_rotation=rot)
        return self._sets[key]

    def scores(self, obs: LocalObservation, state: JointState,
               actions: ActionSet) -> tuple[FloatArray, Lookahead]:
        """``(A,)`` ``reward + γ^(Δt v_pref) V(next)`` (``-inf`` where pruned) and the lookahead."""
        p = self.params
        look = lookahead(state, actions, world_returns(obs), wall_margin=p.wall_margin,
                         wall_soft=p.wall_soft, wall_factor=p.wall_factor)
        feats = rotate(look.next_robot, look.next_humans, actions.holonomic)
        values = self.policy.network.value(feats)
        disc = self.gamma ** (actions.time_step * float(state.robot[7]))
        score = look.rewards + disc * values
        return np.where(look.pruned, -np.inf, score), look

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The command ``(3,)`` ``[vx, vy, omega]``; see the module docstring."""
        p = self.params
        goal = obs.goal_pose
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        if at_goal(obs, math.hypot(goal.x - pose[0], goal.y - pose[1]), p.goal_tolerance):
            self.last, self.last_action = None, -1
            return goal_command(obs, p.heading_gain, p.goal_yaw_tolerance)
        actions = self.action_set(obs)
        state = observe(obs, p, self.v_pref(obs))
        score, look = self.scores(obs, state, actions)
        if self.rng is not None and self.epsilon > 0 and self.rng.random() < self.epsilon:
            allowed = np.flatnonzero(~look.pruned)
            i = int(allowed[self.rng.integers(len(allowed))])
        else:
            i = int(np.argmax(score))
        self.last, self.last_action = look, i
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        return finish_command(actions.twists()[i], twist, obs.limits, float(obs.dt), False)


@LOCAL_PLANNERS.register("crowdnav", tags=("learned",))
class CrowdNavPlanner(ValuePlanner):
    """CADRL value network (CrowdNav's ``cadrl``, multi-human); see the module docstring."""

    network_kind: ClassVar[str] = "cadrl"
    file_name: ClassVar[str] = "crowdnav.npz"

    class Params(ValuePlannerParams):
        """Parameters of ``crowdnav``."""

        model_config = ConfigDict(frozen=True, extra="forbid")


@LOCAL_PLANNERS.register("sarl", tags=("learned",))
class SarlPlanner(ValuePlanner):
    """SARL value network (self-attention over pedestrians); see the module docstring."""

    network_kind: ClassVar[str] = "sarl"
    file_name: ClassVar[str] = "sarl.npz"

    class Params(ValuePlannerParams):
        """Parameters of ``sarl``."""

        model_config = ConfigDict(frozen=True, extra="forbid")

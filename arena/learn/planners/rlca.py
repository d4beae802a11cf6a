"""``rlca``: Long et al. 2018's decentralised collision-avoidance policy, trained by us.

Description:
    "Towards Optimally Decentralized Multi-Robot Collision Avoidance via Deep Reinforcement
    Learning" (Long, Fan, Liao, Liu, Zhang, Pan; ICRA 2018): each robot maps its last three
    laser scans, its goal in polar coordinates and its own velocity to a velocity command with
    a Conv1D scan encoder and a Gaussian policy, trained with PPO whose parameters all robots
    share. The packaged weights (``arena/learn/data/policies/rlca.npz``) were trained here with
    ``arena/learn/data/train/rlca.yaml`` (behaviour cloning of a scripted corridor follower,
    then multi-robot PPO; docs/learning.md, "rlca").

    Inference is numpy alone (:class:`~arena.learn.policy.NumpyPolicy` runs the Conv1D layers
    and the MLP); the observation is rebuilt from the :class:`LocalObservation` by
    :class:`~arena.learn.planners.learned.PolicyPlanner`: ``lidar`` (the last 3 scans
    resampled onto the policy's beams), ``goal`` and ``velocity`` (the measured body twist
    ``[vx, vy, ω]``).

    Our adaptations: the goal is a subgoal ``subgoal_horizon`` m along the global path, as for
    ``rosnav_rl`` (the paper's robots see the final goal, which behind a wall of an indoor map
    gives no usable direction); the scans are the Jackal's 720 beams over 270° instead of 512
    over 180°; the action mean is linear and clipped to the action box (SB3) instead of
    sigmoid/tanh-squashed.

Arguments:
    See :class:`RLCAPlanner.Params`.
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from arena.learn.planners.learned import PolicyParams, PolicyPlanner
from arena.nav.local_planners.base import LOCAL_PLANNERS

RLCA_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "rlca.npz"
"""The packaged policy (``arena/learn/data/policies/rlca.npz``)."""


@LOCAL_PLANNERS.register("rlca", tags=("learned",))
class RLCAPlanner(PolicyPlanner):
    """Long et al.'s multi-robot PPO policy (Conv1D over 3 scans, goal, velocity), numpy only."""

    planner_name: ClassVar[str] = "rlca"
    default_weights: ClassVar[Path] = RLCA_WEIGHTS
    supported_keys: ClassVar[frozenset[str]] = frozenset(
        {"lidar", "goal", "velocity", "last_action"}
    )

    class Params(PolicyParams):
        """Parameters of ``rlca``."""

    def __init__(self, params: Params | None = None) -> None:
        super().__init__(params)

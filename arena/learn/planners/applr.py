"""``applr``: DWA whose parameters a TD3 policy sets every period (Xu et al., ICRA 2021).

Description:
    "APPLR: Adaptive Planner Parameter Learning from Reinforcement" (Xu et al.): a policy trained
    with TD3 does not drive; once per ``period`` (1 s) it chooses the parameters of DWA — speed
    caps, sample counts, the path / goal / obstacle weights, the obstacle cost's decay length (the
    inflation) and the clearance — from the laser scan clipped at 2 m, the local goal in the robot
    frame and the parameters in force; DWA drives with them, its hard checks (admissible velocities,
    clearance, braking) intact. The ranges, the action mapping (``a = 0`` is DWA's default) and the
    observation are in :mod:`arena.learn.applr.space`; the capped DWA is
    :class:`~arena.learn.applr.tuned_dwa.TunedDWA`.

    Timing: the first control cycle after :meth:`ApplrPlanner.reset` drives with DWA's
    defaults; from the next one on, whenever ``period`` s have passed since the last choice
    (or the clock went backwards), the policy chooses from the observation of the previous
    cycle and the new parameters hold from this cycle for one period. The training
    environment (:class:`~arena.learn.applr.env.ApplrEnv`) steps in exactly this rhythm.

    Inference is numpy alone (:class:`~arena.learn.applr.actor.ApplrActor`, an MLP of two
    hidden ReLU layers and a tanh head). The packaged weights
    (``arena/learn/data/policies/applr.npz``) were trained in our simulator on generated
    ``barn`` maps (docs/learning.md, "applr"); without a policy file the planner fails with a
    one-line error instead of falling back to plain DWA.

Arguments:
    See :class:`ApplrPlanner.Params`.
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.learn.applr.actor import ApplrActor
from arena.learn.applr.space import observation
from arena.learn.applr.tuned_dwa import TunedDWA
from arena.nav.local_planners.base import KINEMATICS, LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.dwa import DWAPlanner

APPLR_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "applr.npz"
"""The packaged policy (``arena/learn/data/policies/applr.npz``)."""


@LOCAL_PLANNERS.register("applr", tags=("learned", "hybrid"))
class ApplrPlanner:
    """DWA with parameters chosen every period by a TD3 actor (numpy inference)."""

    supports: ClassVar[frozenset[str]] = KINEMATICS

    class Params(BaseModel):
        """Parameters of ``applr``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        weights: str | None = Field(
            None, description="APPLR policy file (.npz, RUN/policy.npz); None: the packaged one"
        )
        period: float | None = Field(
            None, gt=0, description="s between parameter choices; None: the policy's (1.0)"
        )
        dwa: DWAPlanner.Params = Field(
            default_factory=DWAPlanner.Params,
            description="DWA's parameters; the policy overrides the ones it tunes",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params if params is not None else self.Params()
        self.actor = ApplrActor.load(p.weights if p.weights is not None else APPLR_WEIGHTS)
        self.period = float(p.period if p.period is not None else self.actor.period)
        self.tuned = TunedDWA(p.dwa, self.actor.parameters)
        self.reset()

    def reset(self) -> None:
        """DWA's defaults and a fresh DWA; the next choice comes at the second cycle."""
        self.tuned.reset()
        self._t_set: float | None = None

    def _due(self, time: float) -> bool:
        if self.tuned.last_obs is None:
            return False  # the first cycle: nothing observed yet, DWA's defaults
        if self._t_set is None:
            return True
        elapsed = time - self._t_set
        return not 0.0 <= elapsed < self.period - 1e-9

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Choose the parameters when due (module docstring), then DWA's command."""
        t = float(obs.time)
        prev = self.tuned.last_obs
        if prev is not None and self._due(t):
            x = observation(prev, self.tuned.action, self.actor.features)
            self.tuned.set_action(self.actor.act(x))
            self._t_set = t
        return self.tuned.compute(obs)

"""Reward terms (Arena's reward units, arena_specs §8.4) for N worlds at once.

Each term is a small class registered in :data:`REWARD_TERMS` with a pydantic ``Params``
holding Arena's default (``rewards/constants.py``) and a ``__call__`` that maps a
:class:`RewardInput` (arrays with a leading world axis ``N``) to a :class:`TermResult`.
A :class:`RewardFunction` sums the configured terms like force terms and also returns each
term's share, for logging. A batched environment reuses them unchanged. For the single
environment most terms also have a ``single`` method, the same formula on Python floats
(:class:`SingleRewardInput`, :meth:`RewardFunction.single`), bit-identical and several times
cheaper than numpy on ``(1,)`` arrays.

Reward files (``arena/learn/data/rewards/<name>.yaml``, or an inline mapping) list
``term_name: {params}``; besides a term's own parameters each block may hold

* ``_on_safe_dist_violation`` (bool, default true): whether the term is still evaluated while
  the safe distance is breached (breach ⇔ min laser range ≤ robot radius + safety distance).
  Arena's key, same meaning.
* ``weight`` (float, default 1): multiplies the term (ours; Arena's weights are the values).

Sign convention: every reward/penalty parameter is the value *added* to the reward (the
shipped files use negative numbers for penalties), as in Arena's configs. Deviations from
Arena: ``collision`` uses the simulator's contact flags (Arena: min laser ≤ robot radius; set
``from_laser: true`` to add that check); ``distance_travelled`` charges ``|v|`` and ``|ω|``
(Arena's signed sum pays the robot for reversing); ``reverse_drive`` defaults to −0.01 (the
specs list the magnitude 0.01; every shipped file penalises).
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import yaml
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from arena.core.errors import ConfigError, UnknownNameError, from_validation_error
from arena.core.registry import Entry, Registry

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

REWARDS_DIR = Path(__file__).resolve().parent / "data" / "rewards"
"""Packaged reward files."""

ELDER = 1
"""Pedestrian type code of elders (``AgentType.ELDER``), Arena's ``type 1``."""


class DoneReason(enum.IntEnum):
    """Why a term ends the episode; a larger value wins when several terms fire."""

    NONE = 0
    STEP_LIMIT = 1
    SUCCESS = 2
    COLLISION = 3


@dataclass(frozen=True, eq=False)
class RewardInput:
    """What the terms see, for ``N`` worlds (``M`` pedestrian slots per world).

    Attributes:
        action: ``(N, 3)`` command of this step ``[vx m/s, vy m/s, ω rad/s]``.
        prev_action: ``(N, 3)`` command of the previous step (zeros after a reset).
        goal_distance: ``(N,)`` m, robot to goal after the step.
        prev_goal_distance: ``(N,)`` m, robot to goal before the step (to the same goal).
        goal_jump: ``(N,)`` m, how far the goal moved since the previous step (0: same goal).
        goal_radius: ``(N,)`` m.
        goal_reached: ``(N,)`` bool, the task says the goal is reached.
        min_range: ``(N,)`` m, smallest laser range after the step.
        robot_radius: ``(N,)`` m, Arena's robot radius.
        safe_dist: ``(N,)`` m, robot radius + safety distance.
        collision: ``(N,)`` bool, the simulator reports a contact.
        heading: ``(N,)`` rad after the step.
        prev_heading: ``(N,)`` rad before the step.
        dt: ``(N,)`` s, the step's duration (the action period).
        step: ``(N,)`` env steps taken in the episode, this one included.
        max_steps: ``(N,)`` env steps allowed.
        ped_distance: ``(N, M)`` m, robot centre to each pedestrian centre.
        ped_kind: ``(N, M)`` pedestrian type codes (0 adult, 1 elder, 2 child).
        ped_mask: ``(N, M)`` bool, the slot holds a pedestrian.
    """

    action: FloatArray
    prev_action: FloatArray
    goal_distance: FloatArray
    prev_goal_distance: FloatArray
    goal_jump: FloatArray
    goal_radius: FloatArray
    goal_reached: BoolArray
    min_range: FloatArray
    robot_radius: FloatArray
    safe_dist: FloatArray
    collision: BoolArray
    heading: FloatArray
    prev_heading: FloatArray
    dt: FloatArray
    step: IntArray
    max_steps: IntArray
    ped_distance: FloatArray
    ped_kind: IntArray
    ped_mask: BoolArray

    @property
    def n(self) -> int:
        """Number of worlds."""
        return int(self.goal_distance.shape[0])

    @property
    def safe_dist_breached(self) -> BoolArray:
        """``(N,)`` bool: the min laser range is within the safe distance."""
        return np.asarray(self.min_range <= self.safe_dist)


@dataclass(slots=True, eq=False)
class SingleRewardInput:
    """:class:`RewardInput` of one world as Python scalars (the single env's fast path).

    Same meaning and units as the :class:`RewardInput` fields of the same names, without the
    pedestrian arrays: ``batched`` returns the full ``N = 1`` :class:`RewardInput` for terms
    that have no :meth:`single` method (those on pedestrians, those whose numpy kernels may
    round differently from Python's ``math``). ``action`` and ``prev_action`` are
    ``(vx m/s, vy m/s, ω rad/s)``.
    """

    action: tuple[float, float, float]
    prev_action: tuple[float, float, float]
    goal_distance: float
    prev_goal_distance: float
    goal_jump: float
    goal_radius: float
    goal_reached: bool
    min_range: float
    robot_radius: float
    safe_dist: float
    collision: bool
    heading: float
    prev_heading: float
    dt: float
    step: int
    max_steps: int
    batched: Callable[[], RewardInput]


@dataclass(frozen=True, eq=False)
class TermResult:
    """A term's output: ``reward`` ``(N,)`` and ``done`` ``(N,)`` bool with its ``reason``."""

    reward: FloatArray
    done: BoolArray
    reason: DoneReason = DoneReason.NONE


class RewardTerm(Protocol):
    """One reward unit.

    A term may also define ``single(inp: SingleRewardInput) -> (reward, done, reason)``, the
    same formula on Python floats for one world; it must return the bits ``__call__`` returns
    for ``N = 1`` (only ``+ − * /``, comparisons and ``abs``, in the same order: IEEE float64
    operations round alike in numpy and Python, transcendental functions need not).
    :meth:`RewardFunction.single` uses it when present.
    """

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for ``N`` worlds."""
        ...


REWARD_TERMS: Registry[RewardTerm] = Registry("reward term", entry_points="arena.reward_terms")
"""Every reward term by name (Arena's unit names)."""


class _Params(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


def _result(
    reward: NDArray[Any], done: BoolArray | None = None, reason: DoneReason = DoneReason.NONE
) -> TermResult:
    r = np.asarray(reward, dtype=np.float64)
    d = np.zeros(r.shape, dtype=bool) if done is None else np.asarray(done, dtype=bool)
    return TermResult(r, d, reason)


def _nearest_of_kind(inp: RewardInput, kind: int) -> FloatArray:
    """``(N,)`` m to the nearest pedestrian of ``kind`` (inf when there is none)."""
    d = np.where(inp.ped_mask & (inp.ped_kind == kind), inp.ped_distance, np.inf)
    return d.min(axis=1) if d.shape[1] else np.full(inp.n, np.inf)


@REWARD_TERMS.register("goal_reached")
class GoalReachedTerm:
    """``+reward`` and done (success) when the goal is reached (the env: ρ < goal radius)."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(15.0, description="added on arrival")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        hit = inp.goal_reached
        return _result(hit * self.params.reward, hit, DoneReason.SUCCESS)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        hit = inp.goal_reached
        # float(bool) * reward as numpy's bool -> float64 cast (False * −x is −0.0 in both)
        return float(hit) * self.params.reward, hit, DoneReason.SUCCESS


@REWARD_TERMS.register("collision")
class CollisionTerm:
    """``+reward`` and done (collision) on contact (and, optionally, laser ≤ radius + bumper)."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-10.0, description="added on collision")
        bumper_zone: float = Field(0.05, ge=0, description="m, for from_laser")
        from_laser: bool = Field(False, description="also min laser ≤ robot radius + bumper")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        hit = inp.collision.copy()
        if self.params.from_laser:
            hit |= inp.min_range <= inp.robot_radius + self.params.bumper_zone
        return _result(hit * self.params.reward, hit, DoneReason.COLLISION)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        hit = inp.collision
        if self.params.from_laser:
            hit = hit or inp.min_range <= inp.robot_radius + self.params.bumper_zone
        return float(hit) * self.params.reward, hit, DoneReason.COLLISION


@REWARD_TERMS.register("safe_distance")
class SafeDistanceTerm:
    """``+reward`` while the min laser range is within the safe distance."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.15, description="added per step of breach")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        return _result(inp.safe_dist_breached * self.params.reward)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        breached = inp.min_range <= inp.safe_dist
        return float(breached) * self.params.reward, False, DoneReason.NONE


@REWARD_TERMS.register("no_movement")
class NoMovementTerm:
    """``+reward`` when the commanded forward speed is within ±0.1 m/s."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.01, description="added per idle step")
        tolerance: float = Field(0.1, ge=0, description="m/s")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        return _result((np.abs(inp.action[:, 0]) <= self.params.tolerance) * self.params.reward)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        idle = abs(inp.action[0]) <= self.params.tolerance
        return float(idle) * self.params.reward, False, DoneReason.NONE


@REWARD_TERMS.register("approach_goal")
class ApproachGoalTerm:
    """``factor · Δ``, ``Δ = d_prev − d`` (pos factor if Δ > 0, else neg); skipped on goal jumps."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        pos_factor: float = Field(0.3, description="per m approached")
        neg_factor: float = Field(0.5, description="per m receded")
        goal_update_threshold: float = Field(2.5, gt=0, description="m; a larger jump skips")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        p = self.params
        delta = inp.prev_goal_distance - inp.goal_distance
        r = np.where(delta > 0, p.pos_factor, p.neg_factor) * delta
        return _result(np.where(inp.goal_jump >= p.goal_update_threshold, 0.0, r))

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        p = self.params
        if inp.goal_jump >= p.goal_update_threshold:
            return 0.0, False, DoneReason.NONE
        delta = inp.prev_goal_distance - inp.goal_distance
        return (p.pos_factor if delta > 0 else p.neg_factor) * delta, False, DoneReason.NONE


@REWARD_TERMS.register("distance_travelled")
class DistanceTravelledTerm:
    """``−(|v|·lin_scalar + |ω|·ang_scalar)·consumption_factor``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        consumption_factor: float = Field(0.005, description="per (m/s)")
        lin_vel_scalar: float = 1.0
        ang_vel_scalar: float = 0.001

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        p = self.params
        a = np.abs(inp.action)
        v = a[:, 0] * p.lin_vel_scalar + a[:, 2] * p.ang_vel_scalar
        return _result(-v * p.consumption_factor)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        p = self.params
        v = abs(inp.action[0]) * p.lin_vel_scalar + abs(inp.action[2]) * p.ang_vel_scalar
        return -v * p.consumption_factor, False, DoneReason.NONE


@REWARD_TERMS.register("reverse_drive")
class ReverseDriveTerm:
    """``+reward`` when the commanded forward speed is negative and below ``threshold``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.01, description="added per reversing step")
        threshold: float = Field(0.0, le=0, description="m/s (Arena code default 0)")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        v = inp.action[:, 0]
        return _result(((v < 0) & (v < self.params.threshold)) * self.params.reward)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        v = inp.action[0]
        hit = v < 0 and v < self.params.threshold
        return float(hit) * self.params.reward, False, DoneReason.NONE


@REWARD_TERMS.register("abrupt_velocity_change")
class AbruptVelocityChangeTerm:
    """``−Σ_i factor_i · |a_i − a_prev,i|⁴ / 100`` over the components ``[vx, vy, ω]``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        vel_factors: dict[str, float] = Field(
            default_factory=lambda: {"0": 0.3, "1": 0.07, "2": 0.07},
            description="action component index (str) -> factor",
        )

    def __init__(self, params: Params) -> None:
        self.params = params
        self._idx = np.array([int(k) for k in params.vel_factors], dtype=np.int64)
        self._f = np.array(list(params.vel_factors.values()), dtype=np.float64)

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        d = np.abs(inp.action[:, self._idx] - inp.prev_action[:, self._idx])
        return _result(-(d**4 / 100.0 * self._f).sum(axis=1))


@REWARD_TERMS.register("two_factor_velocity_difference")
class TwoFactorVelocityDifferenceTerm:
    """``−(α·Δvx² + β·Δω²)``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        alpha: float = 0.002
        beta: float = 0.005

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        d = inp.action - inp.prev_action
        return _result(-(self.params.alpha * d[:, 0] ** 2 + self.params.beta * d[:, 2] ** 2))

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        # numpy's ``x ** 2`` is ``x * x`` (np.square), not pow
        d0 = inp.action[0] - inp.prev_action[0]
        d2 = inp.action[2] - inp.prev_action[2]
        return -(self.params.alpha * (d0 * d0) + self.params.beta * (d2 * d2)), False, (
            DoneReason.NONE
        )


@REWARD_TERMS.register("ped_type_safety_distance")
class PedTypeSafetyDistanceTerm:
    """``+reward`` when the nearest pedestrian of ``type`` is closer than ``distance``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        reward: float = -0.25
        distance: float = Field(1.25, gt=0, description="m")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        near = _nearest_of_kind(inp, self.params.type) < self.params.distance
        return _result(near * self.params.reward)


@REWARD_TERMS.register("ped_type_collision")
class PedTypeCollisionTerm:
    """``+reward`` when a pedestrian of ``type`` is within robot radius + bumper zone."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        reward: float = -10.0
        bumper_zone: float = Field(0.05, ge=0, description="m")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        hit = _nearest_of_kind(inp, self.params.type) <= inp.robot_radius + self.params.bumper_zone
        return _result(hit * self.params.reward)


@REWARD_TERMS.register("ped_type_vel_constraint")
class PedTypeVelConstraintTerm:
    """``−penalty_factor · v`` while a pedestrian of ``type`` is within ``active_distance``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        penalty_factor: float = 0.05
        active_distance: float = Field(1.25, gt=0, description="m")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        p = self.params
        near = _nearest_of_kind(inp, p.type) < p.active_distance
        return _result(np.where(near, -p.penalty_factor * inp.action[:, 0], 0.0))


@REWARD_TERMS.register("angular_vel_constraint")
class AngularVelConstraintTerm:
    """``−penalty_factor · ω_est`` when ``ω_est = |Δψ| / dt`` exceeds ``threshold``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        penalty_factor: float = 0.05
        threshold: float | None = Field(None, ge=0, description="rad/s; null: never")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        p = self.params
        if p.threshold is None:
            return _result(np.zeros(inp.n))
        dpsi = (inp.heading - inp.prev_heading + np.pi) % (2 * np.pi) - np.pi
        w = np.abs(dpsi) / inp.dt
        return _result(np.where(w > p.threshold, -p.penalty_factor * w, 0.0))


@REWARD_TERMS.register("rotation_penalty")
class RotationPenaltyTerm:
    """``−factor · |ω|`` when the commanded yaw rate ``|ω|`` exceeds ``threshold`` (Long et al.).

    Long et al. 2018 (eq. 5, ``r_w``) penalise large rotational *commands*, not the measured
    heading change of :class:`AngularVelConstraintTerm`: a robot pinned against a wall still
    pays for asking to spin, and the term needs no estimate from poses.
    """

    class Params(_Params):
        """Parameters, with Long et al.'s values."""

        factor: float = Field(0.1, ge=0, description="per rad/s of commanded |ω|")
        threshold: float = Field(0.7, ge=0, description="rad/s; smaller |ω| is free")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        w = np.abs(inp.action[:, 2])
        return _result(np.where(w > self.params.threshold, -self.params.factor * w, 0.0))

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        w = abs(inp.action[2])
        return (-self.params.factor * w if w > self.params.threshold else 0.0), False, (
            DoneReason.NONE
        )


@REWARD_TERMS.register("max_steps_exceeded")
class MaxStepsExceededTerm:
    """``+reward`` and done (step limit) when the step count reaches ``max_steps``."""

    class Params(_Params):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-10.0, description="added at the step limit")

    def __init__(self, params: Params) -> None:
        self.params = params

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        hit = inp.step >= inp.max_steps
        return _result(hit * self.params.reward, hit, DoneReason.STEP_LIMIT)

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world (:meth:`__call__`'s bits)."""
        hit = inp.step >= inp.max_steps
        return float(hit) * self.params.reward, hit, DoneReason.STEP_LIMIT


# -- composition --------------------------------------------------------------------------------
_META_KEYS = ("_on_safe_dist_violation", "weight")


@dataclass(frozen=True, eq=False)
class RewardOutput:
    """The summed reward ``(N,)``, each term's share ``name -> (N,)``, done flags and reasons."""

    total: FloatArray
    terms: dict[str, FloatArray]
    done: BoolArray
    reason: IntArray

    def reasons(self) -> list[DoneReason]:
        """Per world the :class:`DoneReason`."""
        return [DoneReason(int(r)) for r in self.reason]


@cache
def packaged_reward(name: str) -> dict[str, dict[str, Any]]:
    """The term mapping of a packaged reward file (``default``, ``base_semantic``, ``rule_13``)."""
    path = REWARDS_DIR / f"{name}.yaml"
    if not path.is_file():
        known = sorted(p.stem for p in REWARDS_DIR.glob("*.yaml"))
        raise ConfigError(f"unknown reward file {name!r}; known: {', '.join(known)}")
    data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    return {k: dict(v or {}) for k, v in data.items()}


def validate_reward_spec(
    spec: str | Mapping[str, Any], *, path: str = "reward"
) -> dict[str, tuple[dict[str, Any], BaseModel | None]]:
    """Check a reward spec; return ``term -> (meta keys, validated params)``.

    Raises:
        ConfigError: naming the key path of the first problem.
    """
    if isinstance(spec, str):
        try:
            mapping: Mapping[str, Any] = packaged_reward(spec)
        except ConfigError as e:
            raise ConfigError(e.message, path=path) from None
    elif isinstance(spec, Mapping):
        mapping = spec
    else:
        raise ConfigError(f"expected a reward file name or a mapping, got {spec!r}", path=path)
    out: dict[str, tuple[dict[str, Any], BaseModel | None]] = {}
    for name, block in mapping.items():
        if block is None:
            block = {}
        if not isinstance(block, Mapping):
            raise ConfigError(
                f"expected a mapping of parameters, got {block!r}", path=f"{path}.{name}"
            )
        block = dict(block)
        meta = {k: block.pop(k) for k in _META_KEYS if k in block}
        try:
            meta_checked = _Meta.model_validate(meta)
        except ValidationError as e:
            raise from_validation_error(e, prefix=f"{path}.{name}") from None
        entry, params = _validate_term(name, block, path=f"{path}.{name}")
        out[entry.name] = (meta_checked.model_dump(), params)
    return out


def _validate_term(
    name: str, params: Mapping[str, Any], *, path: str
) -> tuple[Entry[RewardTerm], BaseModel | None]:
    # Not REWARD_TERMS.validate: Arena's ped_type_* units take a parameter named ``type``,
    # which a flat ``{type: name, **params}`` block cannot hold. Same checks, same messages.
    try:
        entry = REWARD_TERMS.entry(name)
    except UnknownNameError as e:
        raise UnknownNameError(e.message, path=path) from None
    model = entry.params_model
    if model is None:
        if params:
            raise ConfigError(f"reward term {name!r} takes no parameters", path=path)
        return entry, None
    try:
        return entry, model.model_validate(dict(params))
    except ValidationError as e:
        raise from_validation_error(e, prefix=path) from None


def build_term(name: str, **params: Any) -> RewardTerm:
    """Build one reward term from its name and parameters (validated)."""
    entry, checked = _validate_term(name, params, path=name)
    factory: Any = entry.obj
    term: RewardTerm = factory(checked) if checked is not None else factory()
    return term


class _Meta(_Params):
    on_safe_dist_violation: bool = Field(True, alias="_on_safe_dist_violation")
    weight: float = 1.0


class RewardFunction:
    """A weighted sum of reward terms (Arena's reward-unit system).

    Args:
        spec: a packaged reward file name or ``{term: {params}}``.
    """

    def __init__(self, spec: str | Mapping[str, Any] = "default") -> None:
        checked = validate_reward_spec(spec)
        self.terms: dict[str, RewardTerm] = {}
        self.weights: dict[str, float] = {}
        self.on_violation: dict[str, bool] = {}
        for name, (meta, params) in checked.items():
            cls: Any = REWARD_TERMS.get(name)
            self.terms[name] = cls(params) if params is not None else cls()
            self.weights[name] = float(meta["weight"])
            self.on_violation[name] = bool(meta["on_safe_dist_violation"])
        # (name, term, weight, on_violation) in file order: one tuple per term for __call__
        self._plan = [
            (name, term, self.weights[name], self.on_violation[name])
            for name, term in self.terms.items()
        ]
        # (term, its ``single`` method or None, weight, on_violation) for :meth:`single`
        self._single_plan: list[tuple[RewardTerm, Any, float, bool]] = [
            (term, getattr(term, "single", None), weight, on_violation)
            for _, term, weight, on_violation in self._plan
        ]

    @property
    def names(self) -> tuple[str, ...]:
        """The configured term names, in file order."""
        return tuple(self.terms)

    def __call__(self, inp: RewardInput) -> RewardOutput:
        """Evaluate every term for ``N`` worlds.

        Per term: ``share = where(active, weight · reward, 0)`` with ``active`` all true for
        terms evaluated during a safe-distance breach, else ``~breached``; ``done`` and the
        largest ``reason`` come from the active worlds. The shortcuts below (no multiplication
        by a weight of 1, no masking of always-active terms, no reason update when nothing
        fired) skip only operations that would leave every value unchanged, so the output is
        bit-identical to the plain formula; they matter because a single env calls this with
        ``N = 1`` every step, where each numpy call costs more than its arithmetic.

        For ``N = 1`` the sum, done flag and reason are kept as Python scalars while every
        term's share has the shape ``(1,)`` (float64 additions in the same order, so the same
        bits) and turned into arrays at the end.
        """
        n = inp.n
        # scalar accumulators (N = 1): total, done, reason; arrays once a share has another shape
        scalar = n == 1
        total_1, done_1, reason_1 = 0.0, False, 0
        total: FloatArray | None = None
        done: BoolArray | None = None
        reason: IntArray | None = None
        calm: BoolArray | None = None  # ~breached, computed once and only when a term needs it
        parts: dict[str, FloatArray] = {}
        for name, term, weight, on_violation in self._plan:
            res = term(inp)
            # A fresh array per term: the shares are returned and must not alias the term's
            # (or the input's) arrays.
            r = res.reward * weight if weight != 1.0 else np.array(res.reward, dtype=np.float64)
            fired = res.done
            if not on_violation:
                if calm is None:
                    calm = ~inp.safe_dist_breached
                r = np.where(calm, r, 0.0)
                fired = fired & calm
            parts[name] = r
            if scalar and r.shape == (1,) and fired.shape == (1,) and fired.dtype == np.bool_:
                total_1 += float(r[0])
                if fired[0]:
                    done_1 = True
                    reason_1 = max(reason_1, int(res.reason))
                continue
            if total is None:  # leave the scalar path (or never take it)
                scalar = False
                total, done, reason = _accumulators(n, total_1, done_1, reason_1)
            assert done is not None
            assert reason is not None
            total += r
            if fired.any():
                done |= fired
                reason = np.where(fired, np.maximum(reason, int(res.reason)), reason)
        if total is None or done is None or reason is None:
            total, done, reason = _accumulators(n, total_1, done_1, reason_1)
        return RewardOutput(total, parts, done, reason)

    def single(self, inp: SingleRewardInput) -> RewardOutput:
        """:meth:`__call__` for one world given as scalars; the same output, bit for bit.

        Terms with a ``single`` method run on Python floats; the others on
        ``inp.batched()`` (built at most once). Per term the share is ``weight · reward`` (no
        multiplication by a weight of 1, as :meth:`__call__`), ``0.0`` for a term switched off
        during a safe-distance breach, and the shares are summed from ``0.0`` in file order: the
        float64 operations of :meth:`__call__`, so the same bits. This path exists because the
        single env evaluates the reward every step, where numpy's per-call cost on ``(1,)``
        arrays is most of the work.
        """
        total, done, reason = 0.0, False, 0
        breached: bool | None = None  # computed once and only when a term needs it
        batched: RewardInput | None = None
        shares: list[float] = []
        for term, single, weight, on_violation in self._single_plan:
            if single is not None:
                r, fired, why = single(inp)
            else:
                if batched is None:
                    batched = inp.batched()
                res = term(batched)
                r, fired, why = float(res.reward[0]), bool(res.done[0]), res.reason
            if weight != 1.0:
                r = r * weight
            if not on_violation:
                if breached is None:
                    breached = inp.min_range <= inp.safe_dist
                if breached:
                    r, fired = 0.0, False
            shares.append(r)
            total += r
            if fired:
                done = True
                reason = max(reason, int(why))
        # a (1,) array per share (cheaper than rows of one (k, 1) array: row views cost more)
        parts = {
            name: np.array([r], np.float64)
            for name, r in zip(self.terms, shares, strict=True)
        }
        return RewardOutput(
            np.array([total]), parts, np.array([done]), np.array([reason], dtype=np.int64)
        )


def _accumulators(
    n: int, total: float, done: bool, reason: int
) -> tuple[FloatArray, BoolArray, IntArray]:
    """The ``(n,)`` arrays of :class:`RewardOutput` filled with the scalar accumulators."""
    # np.array of a short list: a third of np.full's cost (a Python function) for n = 1
    return (
        np.array([total] * n, dtype=np.float64),
        np.array([done] * n, dtype=bool),
        np.array([reason] * n, dtype=np.int64),
    )

"""What reward terms see and return, the term registry, and the one-formula term base.

Each term writes its formula once, in :meth:`Term.formula`, with the few operations that differ
between numpy arrays and Python scalars taken from ``ops`` (:data:`ARRAY` or :data:`SCALAR`):
``where``, ``abs``, ``col`` (a column of an ``(N, k)`` array / an item of a tuple), ``either``
and ``both`` (element-wise or / and). Everything else (``+ − * /``, comparisons, ``bool ·
float``) is written with Python operators, which numpy applies element-wise with the same
IEEE float64 rounding, so one formula gives the same bits on ``N`` worlds and on one world's
scalars. :class:`ScalarTerm` marks formulas that may run on scalars (the single env's fast
path, :meth:`~arena.learn.rewards.function.RewardFunction.single`); terms that need numpy
(transcendental or power functions, per-pedestrian arrays) are :class:`Term` and run on the
``N = 1`` arrays there.
"""

from __future__ import annotations

import abc
import enum
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from arena.core.registry import Registry

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

REWARDS_DIR = Path(__file__).resolve().parent.parent / "data" / "rewards"
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
    pedestrian arrays: ``batched`` returns the full ``N = 1`` :class:`RewardInput` for the
    terms that need numpy (not :class:`ScalarTerm`). ``action`` and ``prev_action`` are
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
    """One reward unit: ``__call__`` maps ``N`` worlds' input to their rewards."""

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for ``N`` worlds."""
        ...


REWARD_TERMS: Registry[RewardTerm] = Registry("reward term", entry_points="arena.reward_terms")
"""Every reward term by name (Arena's unit names)."""


class TermParams(BaseModel):
    """Base of every term's parameters (frozen, unknown keys rejected)."""

    model_config = ConfigDict(frozen=True, extra="forbid")


# -- the operations a formula takes from ``ops`` --------------------------------------------------
class ArrayOps:
    """numpy's forms, for ``N`` worlds (arrays with a leading world axis)."""

    where = staticmethod(np.where)
    abs = staticmethod(np.abs)

    @staticmethod
    def col(a: Any, i: int) -> Any:
        """Column ``i`` of ``(N, k)`` ``a``: ``(N,)``."""
        return a[:, i]

    @staticmethod
    def either(a: Any, b: Any) -> Any:
        """Element-wise ``a or b`` (a new array)."""
        return a | b

    @staticmethod
    def both(a: Any, b: Any) -> Any:
        """Element-wise ``a and b``."""
        return a & b


class ScalarOps:
    """Python's forms, for one world given as scalars (:class:`SingleRewardInput`)."""

    abs = staticmethod(abs)

    @staticmethod
    def where(c: Any, a: Any, b: Any) -> Any:
        """``a if c else b``."""
        return a if c else b

    @staticmethod
    def col(a: Any, i: int) -> Any:
        """Item ``i`` of the tuple ``a``."""
        return a[i]

    @staticmethod
    def either(a: Any, b: Any) -> Any:
        """``a or b``."""
        return a or b

    @staticmethod
    def both(a: Any, b: Any) -> Any:
        """``a and b``."""
        return a and b


ARRAY = ArrayOps()
SCALAR = ScalarOps()
Ops = ArrayOps | ScalarOps


class Term(abc.ABC):
    """A reward term: its :class:`Params` and one :meth:`formula` (see the module doc).

    Attributes:
        reason: why the term ends an episode when its formula says done.
    """

    reason: ClassVar[DoneReason] = DoneReason.NONE

    def __init__(self, params: Any) -> None:
        self.params = params

    @abc.abstractmethod
    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """``(reward, done or None)`` of the term.

        ``(N,)`` arrays for ``ops`` = :data:`ARRAY` on a :class:`RewardInput`; Python scalars for
        :data:`SCALAR` on a :class:`SingleRewardInput` (only :class:`ScalarTerm`).
        """

    def __call__(self, inp: RewardInput) -> TermResult:
        """Rewards ``(N,)`` for the ``N`` worlds of ``inp``."""
        reward, done = self.formula(inp, ARRAY)
        r = np.asarray(reward, dtype=np.float64)
        # a copy: ``done`` may be one of the input's arrays
        d = np.zeros(r.shape, dtype=bool) if done is None else np.array(done, dtype=bool)
        return TermResult(r, d, self.reason)


class ScalarTerm(Term):
    """A term whose formula also runs on one world's Python scalars, bit for bit."""

    def single(self, inp: SingleRewardInput) -> tuple[float, bool, DoneReason]:
        """``(reward, done, reason)`` of one world: :meth:`__call__`'s bits for ``N = 1``."""
        reward, done = self.formula(inp, SCALAR)
        return reward, bool(done), self.reason

"""Reward terms (Arena's reward units, arena_specs §8.4) for N worlds at once.

Each term is a small class registered in :data:`REWARD_TERMS` with a pydantic ``Params``
holding Arena's default (``rewards/constants.py``) and one formula
(:class:`~arena.learn.rewards.base.Term`) mapping a :class:`RewardInput` (arrays with a leading
world axis ``N``) to a :class:`TermResult`. A :class:`RewardFunction` sums the configured terms
like force terms and also returns each term's share, for logging. The batched environment
uses them unchanged; for the single environment most formulas also run on one world's Python
floats (:class:`SingleRewardInput`, :meth:`RewardFunction.single`), the same formula, bit for
bit, several times cheaper than numpy on ``(1,)`` arrays.

Modules: :mod:`~arena.learn.rewards.base` (inputs, outputs, registry, the term base),
:mod:`~arena.learn.rewards.terms` (task and motion terms), :mod:`~arena.learn.rewards.people`
(pedestrian-type terms), :mod:`~arena.learn.rewards.function` (reward files and the sum).

Sign convention: every reward/penalty parameter is the value *added* to the reward (the
shipped files use negative numbers for penalties), as in Arena's configs. Deviations from
Arena: ``collision`` uses the simulator's contact flags (Arena: min laser ≤ robot radius; set
``from_laser: true`` to add that check); ``distance_travelled`` charges ``|v|`` and ``|ω|``
(Arena's signed sum pays the robot for reversing); ``reverse_drive`` defaults to −0.01 (the
specs list the magnitude 0.01; every shipped file penalises).
"""

from arena.learn.rewards import people, terms  # noqa: F401  (registers the terms)
from arena.learn.rewards.base import (
    ELDER,
    REWARD_TERMS,
    REWARDS_DIR,
    DoneReason,
    RewardInput,
    RewardTerm,
    ScalarTerm,
    SingleRewardInput,
    Term,
    TermResult,
)
from arena.learn.rewards.function import (
    RewardFunction,
    RewardOutput,
    build_term,
    packaged_reward,
    validate_reward_spec,
)

__all__ = [
    "ELDER",
    "REWARDS_DIR",
    "REWARD_TERMS",
    "DoneReason",
    "RewardFunction",
    "RewardInput",
    "RewardOutput",
    "RewardTerm",
    "ScalarTerm",
    "SingleRewardInput",
    "Term",
    "TermResult",
    "build_term",
    "packaged_reward",
    "validate_reward_spec",
]

"""The reward function: configured terms summed with weights (Arena's reward-unit system).

Reward files (``arena/learn/data/rewards/<name>.yaml``, or an inline mapping) list
``term_name: {params}``; besides a term's own parameters each block may hold

* ``_on_safe_dist_violation`` (bool, default true): whether the term is still evaluated while
  the safe distance is breached (breach ⇔ min laser range ≤ robot radius + safety distance).
  Arena's key, same meaning.
* ``weight`` (float, default 1): multiplies the term (ours; Arena's weights are the values).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
import yaml
from pydantic import BaseModel, Field, ValidationError

from arena.core.errors import ConfigError, UnknownNameError, from_validation_error
from arena.core.registry import Entry
from arena.learn.rewards.base import (
    REWARD_TERMS,
    REWARDS_DIR,
    SCALAR,
    BoolArray,
    DoneReason,
    FloatArray,
    IntArray,
    RewardInput,
    RewardTerm,
    ScalarTerm,
    SingleRewardInput,
    TermParams,
)

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


class _Meta(TermParams):
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
        # (term, its scalar formula or None, weight, on_violation) for :meth:`single`
        self._single_plan: list[tuple[RewardTerm, Any, float, bool]] = [
            (term, term.formula if isinstance(term, ScalarTerm) else None, weight, on_violation)
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

        :class:`~arena.learn.rewards.base.ScalarTerm` formulas run on Python floats; the others on
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
        for term, formula, weight, on_violation in self._single_plan:
            if formula is not None:
                r, fired = formula(inp, SCALAR)
                why = term.reason  # type: ignore[attr-defined]
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

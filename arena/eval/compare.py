"""Two benchmark runs of the same episodes side by side (e.g. native2d against mujoco).

Runs of the same suite, seed and scale play the same episodes (an episode is a pure function
of its config and seed), so their rows pair up by ``(contestant, stage, episode)``. For each
contestant and metric, :func:`compare_runs` gives both runs' means over the paired episodes
and the mean paired difference ``B − A`` with its percentile bootstrap interval
(:func:`~arena.eval.stats.bootstrap_mean`): a difference whose interval excludes 0 is called
significant. Pairing removes the episode-to-episode spread (one map is harder than another in
both runs), so smaller differences are resolved than by comparing two independent means.
:func:`outcome_changes` lists the episodes whose outcome differs, the ones to watch.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from arena.core.errors import ArenaError
from arena.eval.stats import Estimate, bootstrap_mean
from arena.eval.store import load_results, read_manifest

DEFAULT_METRICS = (
    "success", "collisions", "time_to_goal", "path_length", "min_distance_to_person",
    "personal_space_compliance",
)
"""Metrics compared by default (those ``arena bench`` prints)."""


@dataclass(frozen=True)
class MetricComparison:
    """One contestant's metric in both runs, over the episodes both ran.

    Attributes:
        contestant: the contestant.
        metric: the metric (a results column).
        a: run A's mean (with its bootstrap interval) over the paired episodes.
        b: run B's mean likewise.
        diff: the mean paired difference ``B − A`` and its interval (NaN bounds with fewer
            than :data:`~arena.eval.stats.MIN_N` pairs where both values are finite).
    """

    contestant: str
    metric: str
    a: Estimate
    b: Estimate
    diff: Estimate

    @property
    def significant(self) -> bool:
        """The difference's interval excludes 0."""
        d = self.diff
        return d.has_interval and (d.lower > 0.0 or d.upper < 0.0)


@dataclass(frozen=True)
class OutcomeChange:
    """An episode whose outcome differs between the runs."""

    contestant: str
    stage: str
    episode: int
    a: str
    b: str


@dataclass(frozen=True)
class RunPair:
    """Two loaded runs and their paired rows.

    Attributes:
        simulators: ``(A, B)`` simulator names from the run manifests.
        keys: the ``(contestant, stage, episode)`` keys both runs hold, sorted.
        a_rows: run A's row index of each key; ``b_rows`` likewise.
    """

    a: Any
    b: Any
    simulators: tuple[str, str]
    keys: list[tuple[str, str, int]]
    a_rows: list[int]
    b_rows: list[int]


def pair_runs(run_a: str | Path, run_b: str | Path) -> RunPair:
    """Load two runs and pair their episodes.

    Raises:
        ArenaError: a folder without a run, runs of different suites, seeds or scales, or no
            episode in common.
    """
    ma, mb = read_manifest(run_a), read_manifest(run_b)  # one-line errors for a bad folder
    for key in ("suite", "seed", "scale"):
        va, vb = ma.get(key), mb.get(key)
        if key == "suite":
            va, vb = Path(str(va)).name, Path(str(vb)).name
        if va != vb:
            raise ArenaError(
                f"{run_b}: run.json field {key!r} is {vb!r} but {run_a} has {va!r}; compare "
                "runs of the same suite, seed and scale (the same episodes)"
            )
    a, b = load_results(run_a), load_results(run_b)
    index_a = _index(a)
    index_b = _index(b)
    keys = sorted(index_a.keys() & index_b.keys())
    if not keys:
        raise ArenaError(f"{run_a} and {run_b} have no (contestant, stage, episode) in common")
    return RunPair(a, b, (str(ma.get("simulator", "native2d")), str(mb.get("simulator",
                   "native2d"))), keys, [index_a[k] for k in keys], [index_b[k] for k in keys])


def _index(table: Any) -> dict[tuple[str, str, int], int]:
    c = table.column("contestant").to_pylist()
    s = table.column("stage").to_pylist()
    e = table.column("episode").to_pylist()
    return {(str(ci), str(si), int(ei)): i for i, (ci, si, ei) in enumerate(zip(c, s, e,
                                                                              strict=True))}


def _column(table: Any, name: str, rows: list[int]) -> np.ndarray:
    if name not in table.column_names:
        return np.full(len(rows), np.nan)
    values = np.array([np.nan if v is None else v for v in table.column(name).to_pylist()],
                      dtype=np.float64)
    return values[rows]


def compare_runs(
    pair: RunPair, metrics: Sequence[str] = DEFAULT_METRICS
) -> list[MetricComparison]:
    """Per contestant (in key order) and metric, both means and the paired difference.

    Raises:
        ArenaError: a metric neither run has.
    """
    for m in metrics:
        if m not in pair.a.column_names and m not in pair.b.column_names:
            raise ArenaError(f"no metric {m!r} in the runs; they hold "
                             f"{', '.join(sorted(set(pair.a.column_names)))}")
    who = [k[0] for k in pair.keys]
    out = []
    for contestant in dict.fromkeys(who):
        mine = [i for i, c in enumerate(who) if c == contestant]
        ra = [pair.a_rows[i] for i in mine]
        rb = [pair.b_rows[i] for i in mine]
        for m in metrics:
            va, vb = _column(pair.a, m, ra), _column(pair.b, m, rb)
            both = np.isfinite(va) & np.isfinite(vb)
            out.append(MetricComparison(
                contestant, m, bootstrap_mean(va[both]), bootstrap_mean(vb[both]),
                bootstrap_mean(vb[both] - va[both]),
            ))
    return out


def outcome_changes(pair: RunPair) -> list[OutcomeChange]:
    """The paired episodes whose outcome differs, in key order."""
    oa = pair.a.column("outcome").to_pylist()
    ob = pair.b.column("outcome").to_pylist()
    return [
        OutcomeChange(c, s, e, str(oa[i]), str(ob[j]))
        for (c, s, e), i, j in zip(pair.keys, pair.a_rows, pair.b_rows, strict=True)
        if oa[i] != ob[j]
    ]


def fmt_estimate(e: Estimate, spec: str = "{:.2f}") -> str:
    """``mean [lower, upper]`` (``mean`` alone without an interval, ``–`` without values)."""
    if e.n == 0 or not math.isfinite(e.mean):
        return "–"
    if not e.has_interval:
        return spec.format(e.mean)
    return f"{spec.format(e.mean)} [{spec.format(e.lower)}, {spec.format(e.upper)}]"

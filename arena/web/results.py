"""What a run's results page shows, as JSON: the report's tables and figures' data.

:func:`results_view` computes, from a run's results table, what ``arena report`` draws
(:mod:`arena.eval.report`): the headline table (mean with its bootstrap interval and ``n`` per
contestant × stage, and over all stages), every other metric over all stages, the outcomes per
contestant and the social radar (:func:`arena.eval.plots.radar_values`). The page
(:mod:`arena.web.results_page`) draws it in the browser (ECharts) instead of embedding PNGs.

A bench run's table is :func:`arena.eval.store.load_results`; an ``arena run`` run's is its
``summary.csv``, with the run as the one contestant and each row's stage (its map when the row
has none) as the stage. Views are cached per run folder and its newest file, so a page that
is opened again costs nothing until an episode lands.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from arena.eval import plots
from arena.eval.plots import HEADLINE_METRICS, HIGHER_IS_BETTER
from arena.eval.tables import ALL_STAGES, summary_table
from arena.web.store import RunStore

#: Columns of an ``arena run`` summary that are figures of the run, not metrics.
RUN_KEYS = frozenset({"index", "seed", "steps", "goals_reached", "teleports", "wall_time",
                      "control_ms_mean", "control_ms_p95"})


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def run_columns(name: str, rows: Sequence[Mapping[str, Any]]) -> dict[str, np.ndarray]:
    """An ``arena run`` summary (rows of :meth:`RunStore.results`) as a results table.

    The run is the one contestant; numbers become float columns (missing: NaN).
    """
    if not rows:
        return {}
    keys = [k for k in rows[0] if k not in RUN_KEYS and k != "record"]
    cols: dict[str, np.ndarray] = {"contestant": np.array([name] * len(rows))}
    stage = [str(r.get("stage") or r.get("map") or "") for r in rows]
    cols["stage"] = np.array(stage)
    for k in keys:
        if k in ("stage", "contestant"):
            continue
        values = [r.get(k) for r in rows]
        if all(isinstance(v, float | int) or v in ("", None) for v in values):
            cols[k] = np.array([float(v) if isinstance(v, float | int) else math.nan
                                for v in values])
        else:
            cols[k] = np.array([str(v) for v in values])
    return cols


def results_view(table: Any) -> dict[str, Any]:
    """The page's data for a results table (pyarrow Table or ``{column: array}``).

    Returns:
        ``{"contestants": [...], "stages": [...] (with "(all)" last), "headline": [{metric,
        label, unit, higher}], "summary": [{contestant, stage, metric, n, mean, lower, upper}]``
        (headline metrics, every stage and all stages), ``"metrics": [{metric, unit, higher,
        rows: [{contestant, n, mean, lower, upper}]}]`` (every other metric, all stages),
        ``"outcomes": {contestant: {outcome: count}}``, ``"radar": {contestants, metrics,
        values} | None``, ``"episodes": int``}. Non-finite numbers are ``None``.
    """
    cols = plots.as_columns(table)
    if not cols or not len(cols.get("contestant", ())):
        return {"contestants": [], "stages": [], "headline": [], "summary": [], "metrics": [],
                "outcomes": {}, "radar": None, "episodes": 0}
    metrics = plots.metric_columns(cols)
    headline = [(m, label) for m, label in HEADLINE_METRICS if m in metrics]
    others = [m for m in metrics if m not in dict(headline)]
    contestants = plots.unique_in_order(cols["contestant"])
    stages = plots.unique_in_order(cols["stage"]) if "stage" in cols else [""]

    def estimate(r: Any) -> dict[str, Any]:
        return {"n": r.n, "mean": _finite(r.mean), "lower": _finite(r.lower),
                "upper": _finite(r.upper)}

    summary = [{"contestant": r.contestant, "stage": r.stage, "metric": r.metric, **estimate(r)}
               for r in summary_table(cols, [m for m, _ in headline], overall=True)]
    overall: dict[str, list[dict[str, Any]]] = {m: [] for m in others}
    for r in summary_table(cols, others, overall=True):
        if r.stage == ALL_STAGES:
            overall[r.metric].append({"contestant": r.contestant, **estimate(r)})
    outcomes: dict[str, dict[str, int]] = {c: {} for c in contestants}
    if "outcome" in cols:
        for c, o in zip(cols["contestant"], cols["outcome"], strict=True):
            outcomes[str(c)][str(o)] = outcomes[str(c)].get(str(o), 0) + 1
    try:
        names, radar_metrics, values = plots.radar_values(cols)
        radar: dict[str, Any] | None = {
            "contestants": names, "metrics": radar_metrics,
            "higher": [HIGHER_IS_BETTER.get(m, True) for m in radar_metrics],
            "values": [[_finite(v) for v in row] for row in values.tolist()]}
    except ValueError:  # no social metric in this table
        radar = None
    return {
        "contestants": contestants,
        "stages": [*stages, ALL_STAGES] if len(stages) > 1 else stages,
        "headline": [{"metric": m, "label": label, "unit": plots.metric_unit(m),
                      "higher": HIGHER_IS_BETTER.get(m)} for m, label in headline],
        # one stage: its rows are the overall ones already
        "summary": [s for s in summary if len(stages) > 1 or s["stage"] != ALL_STAGES],
        "metrics": [{"metric": m, "unit": plots.metric_unit(m),
                     "higher": HIGHER_IS_BETTER.get(m), "rows": overall[m]} for m in others],
        "outcomes": outcomes,
        "radar": radar,
        "episodes": len(cols["contestant"]),
    }


def newest_change(folder: Path) -> float:
    """The newest modification time (s since the epoch) of the folder's results files."""
    stamps = [folder.stat().st_mtime]
    for pattern in ("episodes/*/*", "episodes/*/*/*.json", "summary.csv"):
        stamps += [p.stat().st_mtime for p in folder.glob(pattern)]
    return max(stamps)


def run_view(store: RunStore, name: str) -> dict[str, Any]:
    """:func:`results_view` of run ``name`` of ``store`` (cached until a result changes).

    Raises:
        NotFound: no such run.
    """
    folder = store.folder(name)
    return _cached_view(store, name, newest_change(folder))


@lru_cache(maxsize=16)
def _cached_view(store: RunStore, name: str, stamp: float) -> dict[str, Any]:
    folder = store.folder(name)
    if store.kind(folder) == "bench":
        from arena.eval.store import load_results

        return results_view(load_results(folder))
    return results_view(run_columns(name, store.results(name)))

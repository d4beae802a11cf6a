r"""Benchmark tables: the per-cell summary, ``summary.csv`` and the compact LaTeX ``summary.tex``.

:func:`summary_table` reduces the per-episode results table (see :mod:`arena.eval.plots`) to one
:class:`SummaryRow` per contestant × stage × metric: the mean and its 95 % percentile-bootstrap
interval (:func:`arena.eval.stats.bootstrap_mean`), with ``n`` and the low-n flag. With
``overall=True`` each contestant also gets rows over all its episodes, stage :data:`ALL_STAGES`.

:func:`write_tables` writes every metric as CSV (``summary.csv``, the long table) and the paper's
view as LaTeX (``summary.tex``): two booktabs tables, planners × :data:`HEADLINE_METRICS` over
all stages, and the same grouped by stage. ``summary.tex`` needs only the ``booktabs`` package;
``\input{summary.tex}`` it in a document.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from arena.eval import plots
from arena.eval.plots import HEADLINE_METRICS
from arena.eval.stats import MIN_N, RESAMPLES, Estimate, bootstrap_mean

#: Stage name of the rows over all of a contestant's episodes (not a valid stage name).
ALL_STAGES = "(all)"


@dataclass(frozen=True, kw_only=True)
class SummaryRow(Estimate):
    """The mean of one metric for one contestant on one stage, with its interval.

    The :class:`~arena.eval.stats.Estimate` (``n``, ``mean``, ``lower``, ``upper``, ``low_n``,
    ``has_interval``) of one cell, labelled.

    Attributes:
        contestant, stage, metric: the group (``stage`` is :data:`ALL_STAGES` for the pooled
            rows).
        unit: the metric's unit from the registry ("" if unregistered).
    """

    contestant: str
    stage: str
    metric: str
    unit: str


def summary_table(
    table: Any, metrics: Sequence[str] | None = None, *, overall: bool = False
) -> list[SummaryRow]:
    """Mean and bootstrap interval per contestant × stage × metric, in order of appearance.

    Args:
        table: the results table (pyarrow Table or mapping of arrays).
        metrics: metric columns; ``None`` = every numeric non-key column
            (:func:`arena.eval.plots.metric_columns`, integer counts included).
        overall: also one row per contestant × metric over all its episodes, stage
            :data:`ALL_STAGES`, after the contestant's stages.
    """
    cols = plots.as_columns(table)
    names = list(metrics) if metrics is not None else plots.metric_columns(cols)
    who = cols["contestant"]
    stage_col = cols["stage"] if "stage" in cols else np.full(len(who), "")
    stages = plots.unique_in_order(stage_col)
    values = {m: np.asarray(cols[m], np.float64) for m in names}
    rows: list[SummaryRow] = []
    for c in plots.unique_in_order(who):
        groups = [(s, (who == c) & (stage_col == s)) for s in stages]
        if overall:
            groups.append((ALL_STAGES, who == c))
        for s, mask in groups:
            if not mask.any():
                continue
            for m in names:
                e = bootstrap_mean(values[m][mask])
                rows.append(SummaryRow(n=e.n, mean=e.mean, lower=e.lower, upper=e.upper,
                                       confidence=e.confidence, contestant=c, stage=s,
                                       metric=m, unit=plots.metric_unit(m)))
    return rows


def episode_counts(table: Any) -> dict[tuple[str, str], int]:
    """Episodes (rows, whatever their values) per ``(contestant, stage)`` and ``ALL_STAGES``."""
    cols = plots.as_columns(table)
    who = cols["contestant"]
    stage_col = cols["stage"] if "stage" in cols else np.full(len(who), "")
    out: dict[tuple[str, str], int] = {}
    for c, s in zip(who, stage_col, strict=True):
        for key in ((str(c), str(s)), (str(c), ALL_STAGES)):
            out[key] = out.get(key, 0) + 1
    return out


def decimals(values: Sequence[float]) -> int:
    """Decimals that give the largest finite ``|value|`` about 3 significant digits (0 to 3).

    One count per table column, so a column's numbers line up: 0.963 → 3, 12.4 → 1, 123 → 0.
    """
    finite = [abs(v) for v in values if math.isfinite(v)]
    top = max(finite, default=0.0)
    if top == 0.0:
        return 2
    return int(min(3, max(0, 2 - math.floor(math.log10(top)))))


def fmt(x: float, digits: int) -> str:
    """``x`` with ``digits`` decimals, "–" if not finite."""
    return f"{x:.{digits}f}" if math.isfinite(x) else "–"


def write_tables(table: Any, out: str | Path, params: Any = None) -> tuple[Path, Path]:
    """Write ``summary.csv`` (every metric) and ``summary.tex`` (headline tables) into ``out``.

    ``summary.csv``: one row per contestant × stage × metric, the stages followed by
    :data:`ALL_STAGES`; columns ``contestant, stage, metric, unit, n, mean, lower, upper,
    low_n`` (bounds empty where ``n < MIN_N``). ``summary.tex``: :func:`latex_tables`.

    Args:
        table: the results table.
        out: the report folder (created).
        params: the :class:`~arena.eval.metrics.MetricParams` the metrics were computed with
            (named in the LaTeX captions); ``None`` = the defaults (what ``arena bench`` uses).

    Returns:
        The CSV and LaTeX paths.
    """
    from arena.core.files import make_dir

    out = make_dir(out, what="report folder")
    rows = summary_table(table, overall=True)
    csv_path, tex_path = out / "summary.csv", out / "summary.tex"
    with csv_path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["contestant", "stage", "metric", "unit", "n", "mean", "lower", "upper",
                    "low_n"])
        for r in rows:
            bounds = [repr(r.lower), repr(r.upper)] if r.has_interval else ["", ""]
            w.writerow([r.contestant, r.stage, r.metric, r.unit, r.n,
                        repr(r.mean) if r.n else "", *bounds, int(r.low_n)])
    tex_path.write_text(latex_tables(table, params))
    return csv_path, tex_path


# -- LaTeX -----------------------------------------------------------------------------------------
def tex_escape(text: str) -> str:
    """``text`` with LaTeX's special characters escaped (for text mode)."""
    out = []
    for ch in text:
        out.append({"\\": r"\textbackslash{}", "_": r"\_", "&": r"\&", "%": r"\%", "#": r"\#",
                    "$": r"\$", "{": r"\{", "}": r"\}", "^": r"\textasciicircum{}",
                    "~": r"\textasciitilde{}"}.get(ch, ch))
    return "".join(out)


def _tex_header(header: str) -> str:
    """A column header; ``[unit]`` with ``^k`` powers set as ``$^{k}$`` (``m/s^2``)."""
    import re

    parts = re.split(r"\^(-?\d+)", header)
    return "".join(tex_escape(p) if i % 2 == 0 else f"$^{{{p}}}$" for i, p in enumerate(parts))


def _tex_cell(r: SummaryRow | None, digits: int, n_rows: int) -> str:
    r"""``$m^{+u}_{-l}$``; ``$m^{\dagger}$`` for low n; the cell's own n where it differs."""
    if r is None or r.n == 0:
        return "--"
    m = fmt(r.mean, digits)
    if r.has_interval:
        cell = f"${m}^{{+{fmt(r.upper - r.mean, digits)}}}_{{-{fmt(r.mean - r.lower, digits)}}}$"
    elif r.low_n:
        cell = f"${m}^{{\\dagger}}$"
    else:
        cell = f"${m}$"
    if r.n != n_rows:
        cell += rf"\,{{\scriptsize($n{{=}}{r.n}$)}}"
    return cell


def _tex_rows(rows: Sequence[SummaryRow], stage: str, contestants: Sequence[str],
              episodes: dict[tuple[str, str], int], digits: dict[str, int]) -> list[str]:
    cell = {(r.contestant, r.metric): r for r in rows if r.stage == stage}
    lines = []
    for c in contestants:
        n = episodes.get((c, stage), 0)
        if n == 0:
            continue
        cells = [_tex_cell(cell.get((c, m)), digits[m], n) for m, _ in HEADLINE_METRICS]
        lines.append(" & ".join([tex_escape(c), str(n), *cells]) + r" \\")
    return lines


def _caption(params: Any, what: str) -> str:
    from arena.eval.metrics import MetricParams

    p = params if params is not None else MetricParams()
    rule = ("goal reached, fewer than 2 collisions (Arena 3.0 paper)" if p.success_rule == "arena"
            else "goal reached, collisions allowed")
    return (
        f"{what}: mean over episodes with its 95\\,\\% percentile-bootstrap interval "
        f"({RESAMPLES} resamples), written mean$^{{+u}}_{{-l}}$ for the interval "
        f"$[\\mathrm{{mean}}-l, \\mathrm{{mean}}+u]$; $n$: episodes per planner; $^{{\\dagger}}$: "
        f"fewer than {MIN_N} values, no interval; "
        r"($n{=}k$): the cell's own number of values where it differs (time to goal counts "
        f"successful episodes only). Success: {rule}. Private zone: time with a person's body "
        f"closer than {p.private_zone_radius:g}\\,m to the robot's body; personal-space radius "
        f"{p.personal_space_radius:g}\\,m (Hall). Time seen / facing: a person faced the robot "
        "/ the robot faced a person."
    )


def _stage_caption(params: Any) -> str:
    from arena.eval.metrics import MetricParams

    p = params if params is not None else MetricParams()
    return (r"Per stage; notation as in Table~\ref{tab:arena-overall} ($^{\dagger}$: fewer than "
            f"{MIN_N} values, no interval; private zone {p.private_zone_radius:g}\\,m, "
            f"personal-space radius {p.personal_space_radius:g}\\,m).")


def latex_tables(table: Any, params: Any = None) -> str:
    r"""The paper's tables: planners × :data:`HEADLINE_METRICS`, overall and grouped by stage.

    Two ``table*`` floats (full text width in two-column papers) with booktabs rules and
    two-line headers (name, then unit); they fit a 17 cm text width. Needs only
    ``\usepackage{booktabs}``. Labels ``tab:arena-overall`` and ``tab:arena-stages``.

    Args:
        table: the results table.
        params: the metric parameters named in the captions (``None`` = defaults).
    """
    cols = plots.as_columns(table)
    names = [m for m, _ in HEADLINE_METRICS]
    if "stage" not in cols:
        cols = {**cols, "stage": np.full(len(cols["contestant"]), "")}
    for m in names:  # a headline metric the run lacks is a column of dashes
        cols.setdefault(m, np.full(len(cols["contestant"]), np.nan))
    rows = summary_table(cols, names, overall=True)
    contestants = plots.unique_in_order(cols["contestant"])
    stages = plots.unique_in_order(cols["stage"])
    episodes = episode_counts(cols)
    digits = {m: decimals([v for r in rows if r.metric == m for v in (r.mean, r.upper)])
              for m in names}
    ncol = 2 + len(names)
    # two header lines (name, then unit) keep the columns as narrow as their numbers
    split = [(h.split(" [")[0], "[" + h.split(" [")[1] if " [" in h else "")
             for _, h in HEADLINE_METRICS]
    name_line = [(" ".join(n.split()[:-1]) or n) if u else n for n, u in split]
    unit_line = [(n.split()[-1] + " " + u if len(n.split()) > 1 else u) if u else ""
                 for n, u in split]
    head = (" & ".join(["Planner", "$n$", *(_tex_header(h) for h in name_line)]) + " \\\\\n"
            + " & ".join(["", "", *(_tex_header(h) for h in unit_line)]))
    spec = "lr" + "c" * len(names)

    def float_(label: str, caption: str, body: list[str]) -> list[str]:
        return [r"\begin{table*}[htbp]", r"\centering", r"\small",
                r"\setlength{\tabcolsep}{3pt}", r"\renewcommand{\arraystretch}{1.3}",
                rf"\caption{{{caption}}}",
                rf"\label{{{label}}}", rf"\begin{{tabular}}{{{spec}}}", r"\toprule",
                head + r" \\", r"\midrule", *body, r"\bottomrule", r"\end{tabular}",
                r"\end{table*}", ""]

    lines = ["% Arena benchmark tables (arena.eval.tables.latex_tables); needs booktabs.", ""]
    lines += float_("tab:arena-overall", _caption(params, "All stages"),
                    _tex_rows(rows, ALL_STAGES, contestants, episodes, digits))
    body: list[str] = []
    for i, s in enumerate(stages):
        if i:
            body.append(r"\midrule")
        body.append(rf"\multicolumn{{{ncol}}}{{l}}{{\textit{{{tex_escape(s or 'all')}}}}} \\")
        body += _tex_rows(rows, s, contestants, episodes, digits)
    lines += float_("tab:arena-stages", _stage_caption(params), body)
    return "\n".join(lines)


__all__ = ["ALL_STAGES", "SummaryRow", "decimals", "episode_counts", "fmt", "latex_tables",
           "summary_table", "tex_escape", "write_tables"]

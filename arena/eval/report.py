"""Benchmark reports: summary statistics, CSV/LaTeX tables and one self-contained HTML file.

:func:`summary_table` reduces the per-episode results table (see :mod:`arena.eval.plots`) to the
mean and its 95 % confidence interval (Student t) per contestant × stage × metric;
:func:`write_tables` writes that as CSV and as a booktabs LaTeX table; :func:`write_report`
writes a single HTML file with the run info, the summary table and every figure embedded as a
base64 PNG (and optional base64 MP4 videos), so it can be mailed or archived alone.
:func:`main` is the entry point behind ``arena report RUN``.
"""

from __future__ import annotations

import base64
import csv
import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from arena.eval import plots
from arena.eval.record import EpisodeRecord


@dataclass(frozen=True)
class SummaryRow:
    """Mean of one metric for one contestant on one stage.

    Attributes:
        contestant, stage, metric: the group.
        unit: the metric's unit from the registry ("" if unregistered).
        n: number of finite values.
        mean: their mean (NaN if ``n == 0``).
        ci: half-width of the 95 % CI, ``t_{0.975, n-1} · s / √n`` (NaN if ``n < 2``).
    """

    contestant: str
    stage: str
    metric: str
    unit: str
    n: int
    mean: float
    ci: float

    @property
    def lower(self) -> float:
        """Lower CI bound."""
        return self.mean - self.ci

    @property
    def upper(self) -> float:
        """Upper CI bound."""
        return self.mean + self.ci


def _unit(metric: str) -> str:
    from arena.eval.metrics import METRICS

    return METRICS.get(metric).unit if metric in METRICS else ""


def summary_table(
    table: Any, metrics: Sequence[str] | None = None, confidence: float = 0.95
) -> list[SummaryRow]:
    """Mean ± CI per contestant × stage × metric, contestants and stages in order of appearance.

    Args:
        table: the results table (pyarrow Table or mapping of arrays).
        metrics: metric columns; ``None`` = every float non-key column.
        confidence: CI level (default 95 %).
    """
    cols = plots.as_columns(table)
    names = list(metrics) if metrics is not None else plots.metric_columns(cols)
    contestants = plots.unique_in_order(cols["contestant"])
    stage_col = cols["stage"] if "stage" in cols else np.full(len(cols["contestant"]), "")
    stages = plots.unique_in_order(stage_col)
    rows: list[SummaryRow] = []
    for c in contestants:
        for s in stages:
            mask = (cols["contestant"] == c) & (stage_col == s)
            if not mask.any():
                continue
            for m in names:
                mean, ci, n = plots.mean_ci(np.asarray(cols[m], np.float64)[mask], confidence)
                rows.append(SummaryRow(c, s, m, _unit(m), n, mean, ci))
    return rows


def _fmt(x: float, digits: int = 3) -> str:
    return "–" if not math.isfinite(x) else f"{x:.{digits}g}" if abs(x) >= 1000 else (
        f"{x:.{digits}f}")


def _tex(text: str) -> str:
    for a, b in (("\\", r"\textbackslash{}"), ("_", r"\_"), ("&", r"\&"), ("%", r"\%"),
                 ("#", r"\#"), ("$", r"\$"), ("{", r"\{"), ("}", r"\}")):
        text = text.replace(a, b)
    return text


def latex_table(rows: Sequence[SummaryRow], caption: str = "Benchmark results") -> str:
    """A booktabs LaTeX table, one line per row: metric, unit, contestant, stage, n, mean ± CI."""
    lines = [
        r"\begin{table}[htbp]",
        r"\centering",
        rf"\caption{{{_tex(caption)}, mean $\pm$ 95\,\% CI}}",
        r"\begin{tabular}{lllrr}",
        r"\toprule",
        r"Metric & Contestant & Stage & $n$ & Mean $\pm$ CI \\",
        r"\midrule",
    ]
    last = None
    for r in rows:
        if last is not None and r.metric != last:
            lines.append(r"\addlinespace")
        last = r.metric
        unit = f" [{_tex(r.unit)}]" if r.unit not in ("", "1", "-") else ""
        ci = f" $\\pm$ {_fmt(r.ci)}" if math.isfinite(r.ci) else ""
        lines.append(f"{_tex(r.metric)}{unit} & {_tex(r.contestant)} & {_tex(r.stage)} & "
                     f"{r.n} & {_fmt(r.mean)}{ci} \\\\")
    lines += [r"\bottomrule", r"\end{tabular}", r"\end{table}", ""]
    return "\n".join(lines)


def write_tables(table: Any, out: str | Path) -> tuple[Path, Path]:
    """Write ``summary.csv`` and ``summary.tex`` (booktabs, mean ± CI) into the folder ``out``.

    Returns:
        The CSV and LaTeX paths.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = summary_table(table)
    csv_path, tex_path = out / "summary.csv", out / "summary.tex"
    with csv_path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["contestant", "stage", "metric", "unit", "n", "mean", "ci95", "lower",
                    "upper"])
        for r in rows:
            w.writerow([r.contestant, r.stage, r.metric, r.unit, r.n, repr(r.mean), repr(r.ci),
                        repr(r.lower), repr(r.upper)])
    tex_path.write_text(latex_table(rows))
    return csv_path, tex_path


# -- HTML ------------------------------------------------------------------------------------------
_CSS = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1200px;color:#222}
h1{border-bottom:2px solid #444}table{border-collapse:collapse;font-size:0.85em;margin:1em 0}
th,td{padding:2px 8px;border-bottom:1px solid #ddd;text-align:right}
th:first-child,td:first-child,td.l{text-align:left}th{background:#f0f0f0}
.figs{display:flex;flex-wrap:wrap;gap:8px}.figs img{max-width:580px;border:1px solid #ddd}
video{max-width:580px}
"""


def _img(fig: Any, alt: str) -> str:
    data = base64.b64encode(plots.figure_png(fig)).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _summary_html(rows: Sequence[SummaryRow]) -> str:
    contestants = list(dict.fromkeys((r.contestant, r.stage) for r in rows))
    metrics = list(dict.fromkeys(r.metric for r in rows))
    cell = {(r.contestant, r.stage, r.metric): r for r in rows}
    head = "".join(f"<th>{html.escape(c)}<br>{html.escape(s)}</th>" for c, s in contestants)
    body = []
    for m in metrics:
        tds = []
        for c, s in contestants:
            r = cell.get((c, s, m))
            if r is None:
                tds.append("<td>–</td>")
            else:
                ci = f" ± {_fmt(r.ci)}" if math.isfinite(r.ci) else ""
                tds.append(f"<td>{_fmt(r.mean)}{ci}</td>")
        body.append(f"<tr><td>{html.escape(plots.metric_label(m))}</td>{''.join(tds)}</tr>")
    return (f"<table><tr><th>metric</th>{head}</tr>{''.join(body)}</table>")


def _load_records(
    cols: Mapping[str, np.ndarray], run_dir: Path, mask: np.ndarray, limit: int
) -> list[EpisodeRecord]:
    from arena.eval.io import load_record

    out: list[EpisodeRecord] = []
    if "record" not in cols:
        return out
    for rel in cols["record"][mask]:
        if len(out) >= limit:
            break
        if not rel:
            continue
        p = run_dir / str(rel)
        if p.is_file():
            try:
                out.append(load_record(p))
            except Exception:
                continue
    return out


def episode_grid(record: EpisodeRecord) -> Any:
    """The map an episode ran on, obstacles burnt in, rebuilt from its recorded config.

    Episodes are pure functions of (config, seed, index), so redrawing episode
    ``record.meta.episode`` from ``record.meta.config`` gives the same map and obstacles,
    generated or not. ``None`` if the record has no config or it no longer loads.
    """
    from arena.config.schema import ExperimentConfig
    from arena.core.errors import ArenaError
    from arena.experiment import planning_grid
    from arena.tasks.generator import TaskGenerator

    if not record.meta.config:
        return None
    try:
        cfg = ExperimentConfig.model_validate(record.meta.config)
        return planning_grid(TaskGenerator.from_config(cfg).episode(record.meta.episode))
    except (ArenaError, ValueError):
        return None


def _grid_for(
    grids: Any, records: Sequence[EpisodeRecord]
) -> tuple[Any, Sequence[EpisodeRecord]]:
    """The background grid for a trajectory plot and the records that belong on it.

    With ``grids=None`` the maps are rebuilt from the records' configs; records on another map
    than the first (generated maps change per episode) are left out of that plot.
    """
    if not records:
        return None, records
    if isinstance(grids, Mapping):
        return grids.get(records[0].meta.map_name), records
    if grids is not None:
        return grids, records
    first = episode_grid(records[0])
    if first is None:
        return None, records
    same = [records[0]]
    for r in records[1:]:
        g = episode_grid(r)
        if g is not None and g == first:
            same.append(r)
    return first, same


def write_report(
    table: Any,
    run_dir: str | Path,
    out_html: str | Path,
    *,
    grids: Any = None,
    videos: Sequence[str | Path] = (),
    title: str = "Arena benchmark report",
    kinds: Sequence[plots.PlotKind] = plots.PLOT_KINDS,
    metrics: Sequence[str] | None = None,
    trajectories_per_group: int = 5,
) -> Path:
    """Write one self-contained HTML report (no external assets).

    Contents: title, run info (run folder, manifest fields if ``run.json`` exists, episodes,
    contestants, stages, outcome counts), the summary table (mean ± 95 % CI), one figure per
    metric and plot kind split by stage, the social radar chart, trajectory plots per contestant
    and stage (records loaded from ``run_dir / table["record"]``), and the ``videos`` (MP4 files)
    embedded as base64.

    Args:
        table: the results table.
        run_dir: the run folder (records are resolved relative to it).
        out_html: the HTML file to write.
        grids: an :class:`~arena.maps.grid.OccupancyGrid` for every trajectory plot, or a mapping
            ``map_name -> grid``; ``None`` = rebuild each episode's map from its recorded config
            (:func:`episode_grid`; blank background if that fails).
        videos: MP4 files to embed.
        title: page title.
        kinds: plot kinds to draw per metric.
        metrics: metrics to plot and tabulate; ``None`` = all float non-key columns.
        trajectories_per_group: episodes drawn per contestant × stage trajectory plot.

    Returns:
        The HTML path.
    """
    run_dir = Path(run_dir)
    out_html = Path(out_html)
    cols = plots.as_columns(table)
    names = list(metrics) if metrics is not None else plots.metric_columns(cols)
    contestants = plots.unique_in_order(cols["contestant"])
    stages = plots.unique_in_order(cols["stage"]) if "stage" in cols else [""]
    n_rows = len(cols["contestant"])
    parts = [f"<h1>{html.escape(title)}</h1>"]

    info: list[tuple[str, str]] = [("run folder", str(run_dir)),
                                   ("generated", datetime.now(UTC).isoformat(
                                       timespec="seconds"))]
    manifest = run_dir / "run.json"
    if manifest.is_file():
        try:
            import json

            data = json.loads(manifest.read_text())
            if isinstance(data, dict):
                info += [(str(k), v if isinstance(v, str) else json.dumps(v)[:300])
                         for k, v in data.items() if not isinstance(v, dict | list)
                         or len(json.dumps(v)) <= 300]
        except (OSError, ValueError):
            pass
    info += [("episodes", str(n_rows)), ("contestants", ", ".join(contestants)),
             ("stages", ", ".join(stages))]
    if "outcome" in cols:
        outcomes, counts = np.unique(cols["outcome"].astype(str), return_counts=True)
        info.append(("outcomes", ", ".join(f"{o}: {n}" for o, n in
                                           zip(outcomes, counts, strict=True))))
    parts.append("<h2>Run</h2><table>" + "".join(
        f'<tr><td class="l">{html.escape(k)}</td><td class="l">{html.escape(v)}</td></tr>'
        for k, v in info) + "</table>")

    parts.append("<h2>Summary (mean ± 95 % CI)</h2>")
    parts.append(_summary_html(summary_table(table, names)))

    by_stage = len(stages) > 1
    for m in names:
        if not np.isfinite(np.asarray(cols[m], np.float64)).any():
            continue
        figs = [_img(plots.plot_metric(table, m, k, by_stage=by_stage), f"{m} {k}")
                for k in kinds]
        parts.append(f"<h3>{html.escape(plots.metric_label(m))}</h3>"
                     f'<div class="figs">{"".join(figs)}</div>')

    social = [m for m in plots.SOCIAL_METRICS if m in cols and m in names]
    if social and len(contestants) > 1:
        parts.append("<h2>Social metrics</h2>" + _img(plots.plot_radar(table, social), "radar"))

    traj = []
    for c in contestants:
        for s in stages:
            mask = cols["contestant"] == c
            if "stage" in cols:
                mask &= cols["stage"] == s
            recs = _load_records(cols, run_dir, mask, trajectories_per_group)
            if recs:
                grid, shown = _grid_for(grids, recs)
                fig = plots.plot_trajectories(shown, grid, title=f"{c} / {s}" if s else c)
                traj.append(_img(fig, f"trajectories {c} {s}"))
    if traj:
        parts.append(f'<h2>Trajectories</h2><div class="figs">{"".join(traj)}</div>')

    vids = []
    for v in videos:
        data = base64.b64encode(Path(v).read_bytes()).decode("ascii")
        vids.append(f"<figure><video controls src=\"data:video/mp4;base64,{data}\"></video>"
                    f"<figcaption>{html.escape(Path(v).name)}</figcaption></figure>")
    if vids:
        parts.append(f'<h2>Videos</h2><div class="figs">{"".join(vids)}</div>')

    doc = (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
           f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
           + "\n".join(parts) + "</body></html>\n")
    out_html.parent.mkdir(parents=True, exist_ok=True)
    out_html.write_text(doc, encoding="utf-8")
    return out_html


def main(
    run_dir: str | Path,
    out: str | Path | None = None,
    *,
    grids: Any = None,
    videos: Sequence[str | Path] = (),
) -> dict[str, Path]:
    """``arena report RUN``: load the run's results and write ``report.html`` and the tables.

    Args:
        run_dir: a benchmark run folder (see :mod:`arena.eval.store`).
        out: output folder; default ``<run_dir>/report``.
        grids: occupancy grid(s) for the trajectory plots (see :func:`write_report`).
        videos: MP4 files to embed.

    Returns:
        ``{"html": ..., "csv": ..., "tex": ...}`` paths.
    """
    from arena.eval.store import load_results

    run = Path(run_dir)
    dest = Path(out) if out is not None else run / "report"
    table = load_results(run)
    csv_path, tex_path = write_tables(table, dest)
    html_path = write_report(table, run, dest / "report.html", grids=grids, videos=videos)
    return {"html": html_path, "csv": csv_path, "tex": tex_path}


__all__ = ["SummaryRow", "latex_table", "main", "summary_table", "write_report", "write_tables"]

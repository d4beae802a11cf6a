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
    from arena.core.files import make_dir

    out = make_dir(out, what="report folder")
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
body{font-family:system-ui,'DejaVu Sans',sans-serif;margin:2em auto;max-width:1200px;
padding:0 1em;color:#222;line-height:1.35}
h1{border-bottom:2px solid #444}h2{margin-top:1.6em;border-bottom:1px solid #ccc}
.scroll{overflow-x:auto;max-width:100%}
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0 1em}
th,td{padding:2px 10px;border-bottom:1px solid #ddd;text-align:right;white-space:nowrap}
th:first-child,td:first-child,td.l{text-align:left}th{background:#f0f0f0}
td.l{white-space:normal;word-break:break-all}
.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(520px,1fr));gap:8px}
.figs img{width:100%;height:auto;border:1px solid #ddd}
.traj img,.wide img{display:block;max-width:100%;height:auto;margin:0 auto 1.5em}
details{margin:0.3em 0}summary{cursor:pointer;font-weight:bold;font-size:1.05em;
padding:0.3em 0}
.vids{display:flex;flex-wrap:wrap;gap:12px}.vids figure{margin:0}
video{max-width:560px;width:100%;background:#000}figcaption{font-size:0.85em;color:#555}
"""

#: Metrics whose figures are expanded in the HTML report (the others are collapsed).
OPEN_METRICS: tuple[str, ...] = ("success", "collisions", "time_to_goal", "path_length", "spl",
                                 "personal_space_compliance", "cf_displacement_mean")


def _img(fig: Any, alt: str) -> str:
    data = base64.b64encode(plots.figure_png(fig)).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _metric_images(
    table: Any, metric: str, kinds: Sequence[plots.PlotKind], by_stage: bool
) -> list[str]:
    """The ``<img>`` tags of one metric's plots (a top-level function: it runs in workers)."""
    return [_img(plots.plot_metric(table, metric, k, by_stage=by_stage), f"{metric} {k}")
            for k in kinds]


def _all_metric_images(
    table: Any, metrics: Sequence[str], kinds: Sequence[plots.PlotKind], by_stage: bool,
    workers: int,
) -> list[list[str]]:
    """:func:`_metric_images` for every metric, in ``workers`` processes (1: in this one)."""
    if workers <= 1 or len(metrics) < 2:
        return [_metric_images(table, m, kinds, by_stage) for m in metrics]
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
        futures = [pool.submit(_metric_images, table, m, list(kinds), by_stage)
                   for m in metrics]
        return [f.result() for f in futures]


def _summary_html(rows: Sequence[SummaryRow]) -> str:
    """One table per stage: a row per metric, a column per contestant (mean ± CI)."""
    stages = list(dict.fromkeys(r.stage for r in rows))
    out = []
    for stage in stages:
        sub = [r for r in rows if r.stage == stage]
        contestants = list(dict.fromkeys(r.contestant for r in sub))
        metrics = list(dict.fromkeys(r.metric for r in sub))
        cell = {(r.contestant, r.metric): r for r in sub}
        head = "".join(f"<th>{html.escape(c)}</th>" for c in contestants)
        body = []
        for m in metrics:
            tds = []
            for c in contestants:
                r = cell.get((c, m))
                if r is None:
                    tds.append("<td>–</td>")
                else:
                    ci = f" ± {_fmt(r.ci)}" if math.isfinite(r.ci) else ""
                    tds.append(f"<td>{_fmt(r.mean)}{ci}</td>")
            body.append(f"<tr><td>{html.escape(plots.metric_label(m))}</td>{''.join(tds)}</tr>")
        n = max((r.n for r in sub), default=0)
        caption = f"<h3>{html.escape(stage)} <small>(n ≤ {n})</small></h3>" if stage else ""
        out.append(f'{caption}<div class="scroll"><table><tr><th>metric</th>{head}</tr>'
                   f"{''.join(body)}</table></div>")
    return "".join(out)


def _poster(video: Path) -> str:
    """The poster of a video as a ``data:image/png`` URI ("" if there is none).

    The episode's last frame (``final.png`` beside the video, written by ``run_episode``: it
    shows the whole trajectory and the outcome), else the video's first frame.
    """
    final = video.with_name("final.png")
    if final.is_file():
        return "data:image/png;base64," + base64.b64encode(final.read_bytes()).decode("ascii")
    try:
        import io

        import imageio.v3 as iio
        from PIL import Image

        frame = next(iter(iio.imiter(video, extension=".mp4")))  # imageio-ffmpeg
        buf = io.BytesIO()
        Image.fromarray(np.asarray(frame)).save(buf, format="PNG", optimize=True)
    except Exception:
        return ""
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


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


def _episode_grids(
    grids: Any, episodes: Mapping[int, Sequence[tuple[str, EpisodeRecord]]]
) -> dict[int, Any]:
    """Each episode's background grid.

    From ``grids`` (one grid, or ``map_name -> grid``) or, with ``grids=None``, rebuilt from
    the episode's recorded config (:func:`episode_grid`; the map does not depend on the
    contestant, so the first record of the episode is used).
    """
    out: dict[int, Any] = {}
    for e, paths in episodes.items():
        rec = paths[0][1]
        if isinstance(grids, Mapping):
            out[e] = grids.get(rec.meta.map_name)
        elif grids is not None:
            out[e] = grids
        else:
            out[e] = episode_grid(rec)
    return out


def stage_trajectories(
    cols: Mapping[str, np.ndarray],
    run_dir: Path,
    stage: str | None,
    *,
    grids: Any = None,
    max_episodes: int = 9,
) -> tuple[list[plots.TrajectoryPanel], str]:
    """The trajectory panels of one stage (see :func:`arena.eval.plots.trajectory_panels`).

    Loads the records of the stage's first ``max_episodes`` episodes (every contestant; the
    episode index is the table's ``episode`` column, else the record's), groups them by
    episode and finds each episode's map: one panel if all episodes share a map, else one
    panel per episode. ``stage=None`` = every row.
    """
    from arena.eval.io import load_record

    if "record" not in cols:
        return [], ""
    n = len(cols["contestant"])
    mask = np.ones(n, bool) if stage is None or "stage" not in cols else cols["stage"] == stage
    idx = np.flatnonzero(mask)
    ep_col = cols.get("episode")
    keys = [int(ep_col[i]) if ep_col is not None else -1 for i in idx]
    wanted = set(sorted(k for k in set(keys))[:max(1, max_episodes)]) if ep_col is not None \
        else None
    episodes: dict[int, list[tuple[str, EpisodeRecord]]] = {}
    total: set[int] = set(keys)
    for i, key in zip(idx, keys, strict=True):
        if wanted is not None and key not in wanted:
            continue
        rel = cols["record"][i]
        p = run_dir / str(rel)
        if not rel or not p.is_file():
            continue
        try:
            rec = load_record(p)
        except Exception:
            continue
        e = key if ep_col is not None else int(rec.meta.episode)
        if ep_col is None:
            total.add(e)
            if e not in episodes and len(episodes) >= max_episodes:
                continue
        episodes.setdefault(e, []).append((str(cols["contestant"][i]), rec))
    total.discard(-1)
    return plots.trajectory_panels(episodes, _episode_grids(grids, episodes),
                                   max_panels=max_episodes, total=len(total))


def write_report(
    table: Any,
    run_dir: str | Path,
    out_html: str | Path,
    *,
    grids: Any = None,
    videos: Sequence[str | Path | tuple[str | Path, str]] = (),
    title: str = "Arena benchmark report",
    kinds: Sequence[plots.PlotKind] = plots.PLOT_KINDS,
    metrics: Sequence[str] | None = None,
    trajectory_episodes: int = 9,
    workers: int = 1,
) -> Path:
    """Write one self-contained HTML report (no external assets).

    Contents: title, run info (run folder, manifest fields if ``run.json`` exists, episodes,
    contestants, stages, outcome counts), the summary table (mean ± 95 % CI), one figure per
    metric and plot kind split by stage, the social radar chart, one trajectory figure per stage
    (small multiples, every contestant in its colour; records loaded from
    ``run_dir / table["record"]``, see :func:`stage_trajectories`), and the ``videos`` (MP4
    files) embedded as base64, each with its first frame as poster.

    Args:
        table: the results table.
        run_dir: the run folder (records are resolved relative to it).
        out_html: the HTML file to write.
        grids: an :class:`~arena.maps.grid.OccupancyGrid` for every trajectory plot, or a mapping
            ``map_name -> grid``; ``None`` = rebuild each episode's map from its recorded config
            (:func:`episode_grid`; blank background if that fails).
        videos: MP4 files to embed, each a path or a ``(path, caption)`` pair (default
            caption: the file's folder and name).
        title: page title.
        kinds: plot kinds to draw per metric.
        metrics: metrics to plot and tabulate; ``None`` = all float non-key columns.
        trajectory_episodes: most episodes per stage in the trajectory figure (one panel per
            episode where each episode has its own map, else one shared panel).
        workers: processes drawing the metric figures.

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
    plotted = [m for m in names if np.isfinite(np.asarray(cols[m], np.float64)).any()]
    opened = {m for m in OPEN_METRICS if m in plotted} or set(plotted[:4])
    if plotted:
        parts.append("<h2>Metrics</h2><p>Per metric: mean with 95 % CI (bar), box, violin and "
                     "strip plots by contestant and stage; click a metric to expand it.</p>")
    images = _all_metric_images(table, plotted, kinds, by_stage, workers)
    for m, figs in zip(plotted, images, strict=True):
        parts.append(f"<details{' open' if m in opened else ''}><summary>"
                     f"{html.escape(plots.metric_label(m))}</summary>"
                     f'<div class="figs">{"".join(figs)}</div></details>')

    social = [m for m in plots.SOCIAL_METRICS if m in cols and m in names]
    if social and len(contestants) > 1:
        parts.append('<h2>Social metrics</h2><div class="wide">'
                     + _img(plots.plot_radar(table, social), "radar") + "</div>")

    traj = []
    for s in stages:
        panels, note = stage_trajectories(cols, run_dir, s if "stage" in cols else None,
                                          grids=grids, max_episodes=trajectory_episodes)
        if panels:
            fig = plots.plot_stage_trajectories(
                panels, contestants, title=f"Trajectories: {s}" if s else "Trajectories",
                note=note)
            traj.append(_img(fig, f"trajectories {s}"))
    if traj:
        parts.append(f'<h2>Trajectories</h2><div class="traj">{"".join(traj)}</div>')

    vids = []
    for v in videos:
        path, caption = (Path(v[0]), v[1]) if isinstance(v, tuple) else (
            Path(v), "/".join(Path(v).parts[-2:]))
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        poster = _poster(path)
        attr = f' poster="{poster}"' if poster else ""
        vids.append(f'<figure><video controls preload="metadata"{attr} '
                    f'src="data:video/mp4;base64,{data}"></video>'
                    f"<figcaption>{html.escape(caption)}</figcaption></figure>")
    if vids:
        parts.append(f'<h2>Videos</h2><div class="vids">{"".join(vids)}</div>')

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
    videos: Sequence[str | Path | tuple[str | Path, str]] = (),
    video_episodes: int = 1,
    workers: int = 1,
) -> dict[str, Path]:
    """``arena report RUN``: load the run's results and write ``report.html`` and the tables.

    Args:
        run_dir: a benchmark run folder (see :mod:`arena.eval.store`).
        out: output folder; default ``<run_dir>/report``.
        grids: occupancy grid(s) for the trajectory plots (see :func:`write_report`).
        videos: further MP4 files to embed (see :func:`write_report`).
        video_episodes: episodes re-simulated as videos for every contestant, chosen where the
            contestants differ most (:func:`arena.eval.replay.pick_episodes`); written under
            ``<out>/videos``.
        workers: processes drawing the figures and rendering the videos.

    Returns:
        ``{"html": ..., "csv": ..., "tex": ...}`` paths.
    """
    from arena.eval.store import load_results

    run = Path(run_dir)
    dest = Path(out) if out is not None else run / "report"
    table = load_results(run)
    csv_path, tex_path = write_tables(table, dest)
    clips: list[str | Path | tuple[str | Path, str]] = []
    if video_episodes > 0:
        from arena.eval.replay import episode_videos

        for v in episode_videos(run, table, dest / "videos", count=video_episodes,
                                workers=workers):
            note = "" if v.matches_record else " (re-simulation differs from the record)"
            clips.append((v.path, v.caption + note))
    clips.extend(videos)
    html_path = write_report(table, run, dest / "report.html", grids=grids, videos=clips,
                             workers=workers)
    return {"html": html_path, "csv": csv_path, "tex": tex_path}


__all__ = ["SummaryRow", "latex_table", "main", "summary_table", "write_report", "write_tables"]

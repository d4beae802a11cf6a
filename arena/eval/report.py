"""Benchmark reports: one self-contained HTML file, the tables and every figure as PDF and SVG.

:func:`write_report` writes a single HTML page that leads with the paper's view: the headline
tables (planners × :data:`~arena.eval.plots.HEADLINE_METRICS`, overall and per stage, mean with
its bootstrap interval and n, :mod:`arena.eval.stats`) and one grouped-bar figure per headline
metric; every other metric follows in a collapsible section, then the radar chart, the
trajectories, the per-episode outcome table (rows link to each episode's trajectory) and the
videos. Figures are embedded as base64 PNGs (the page can be mailed or archived alone) and also
saved as PDF and SVG under ``figures/`` beside the page (stable names: ``headline_<metric>``,
``metric_<metric>``, ``radar``, ``trajectories_<stage>``). :func:`main` is the entry
point behind ``arena report RUN``; the tables come from :mod:`arena.eval.tables`.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from arena.eval import plots
from arena.eval.plots import HEADLINE_METRICS
from arena.eval.report_trajectories import (
    OPEN_TARGET_JS,
    episode_section,
    episode_thumbnails,
    stage_trajectories,
)
from arena.eval.stats import MIN_N, RESAMPLES
from arena.eval.tables import (
    ALL_STAGES,
    SummaryRow,
    decimals,
    episode_counts,
    fmt,
    summary_table,
    write_tables,
)
from arena.eval.trajectory_plots import plot_stage_trajectories

_CSS = """
body{font-family:system-ui,'DejaVu Sans',sans-serif;margin:2em auto;max-width:1200px;
padding:0 1em;color:#222;line-height:1.35}
h1{border-bottom:2px solid #444}h2{margin-top:1.6em;border-bottom:1px solid #ccc}
.scroll{overflow-x:auto;max-width:100%}.tall{max-height:36em;overflow-y:auto}
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0 1em}
th,td{padding:2px 10px;border-bottom:1px solid #ddd;text-align:right;white-space:nowrap}
th:first-child,td:first-child,td.l{text-align:left}th{background:#f0f0f0;position:sticky;top:0}
td.l{white-space:normal}td.info{word-break:break-all}
.iv{color:#666;font-size:0.9em}.lown{color:#b35900}caption{text-align:left;color:#555;
font-size:0.9em;caption-side:bottom;padding-top:0.3em}
tr.o-collision td,tr.o-timeout td,tr.o-error td{background:#fff4f0}
.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(520px,1fr));gap:8px}
.figs img{width:100%;height:auto;border:1px solid #ddd}
.thumbs{display:flex;flex-wrap:wrap;gap:8px}.thumbs figure{margin:0}
.thumbs figure:target img{outline:3px solid #e08000}
.traj img,.wide img{display:block;max-width:100%;height:auto;margin:0 auto 1.5em}
details{margin:0.3em 0}summary{cursor:pointer;font-weight:bold;font-size:1.05em;
padding:0.3em 0}
.vids{display:flex;flex-wrap:wrap;gap:12px}.vids figure{margin:0;width:100%;max-width:960px}
video{width:100%;max-width:960px;min-width:min(720px,100%);background:#000}
figcaption{font-size:0.85em;color:#555}
"""


def _figure_tag(fig: Any, alt: str, stem: Path | None) -> str:
    """The ``<img>`` tag (base64 PNG) of ``fig``; also saves ``stem.pdf`` and ``stem.svg``."""
    if stem is not None:
        plots.save_formats(fig, stem)
    data = base64.b64encode(plots.figure_png(fig)).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def figure_stem(fig_dir: Path | None, name: str) -> Path | None:
    """``fig_dir / name`` with characters outside ``A-Za-z0-9._-`` replaced by ``_``."""
    if fig_dir is None:
        return None
    safe = "".join(ch if ch.isalnum() or ch in "._-" else "_" for ch in name)
    return fig_dir / safe


def _metric_images(
    table: Any, metric: str, kinds: Sequence[plots.PlotKind], by_stage: bool,
    fig_dir: Path | None, prefix: str,
) -> list[str]:
    """The ``<img>`` tag of one metric's figure, one panel per kind (runs in workers)."""
    # headline figures carry the tables' column names ("Time facing", not the metric's name)
    title = dict(HEADLINE_METRICS)[metric].split(" [")[0] if prefix == "headline" else None
    fig = plots.plot_metric(table, metric, kinds, by_stage=by_stage, title=title)
    return [_figure_tag(fig, f"{metric} {', '.join(kinds)}",
                        figure_stem(fig_dir, f"{prefix}_{metric}"))]


def _all_metric_images(
    table: Any, metrics: Sequence[str], kinds: Sequence[plots.PlotKind], by_stage: bool,
    workers: int, fig_dir: Path | None, prefix: str,
) -> list[list[str]]:
    """:func:`_metric_images` for every metric, in ``workers`` processes (1: in this one)."""
    if workers <= 1 or len(metrics) < 2:
        return [_metric_images(table, m, kinds, by_stage, fig_dir, prefix) for m in metrics]
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
        futures = [pool.submit(_metric_images, table, m, list(kinds), by_stage, fig_dir, prefix)
                   for m in metrics]
        return [f.result() for f in futures]


def _cell_html(r: SummaryRow | None, digits: int, n_rows: int) -> str:
    """``mean [lower, upper]``; low-n cells flagged ``n=k`` without interval."""
    if r is None or r.n == 0:
        return "<td>–</td>"
    text = fmt(r.mean, digits)
    if r.has_interval:
        text += f' <span class="iv">[{fmt(r.lower, digits)}, {fmt(r.upper, digits)}]</span>'
    elif r.low_n:
        text += f' <span class="lown" title="fewer than {MIN_N} values">n={r.n}†</span>'
    if r.n != n_rows and not r.low_n:
        text += f' <span class="iv">n={r.n}</span>'
    return f"<td>{text}</td>"


def summary_html(rows: Sequence[SummaryRow], metrics: Sequence[str],
                 episodes: Mapping[tuple[str, str], int],
                 headers: Sequence[str] | None = None) -> str:
    """One table per stage: a row per contestant, a column per metric, ``mean [lower, upper]``.

    ``rows`` come from :func:`~arena.eval.tables.summary_table` (with ``overall=True`` the
    :data:`~arena.eval.tables.ALL_STAGES` table comes first); each column keeps one number of
    decimals; ``n`` is the contestant's episodes on the stage
    (:func:`~arena.eval.tables.episode_counts`), a cell with fewer values shows its own n.
    """
    stages = list(dict.fromkeys(r.stage for r in rows))
    if ALL_STAGES in stages:
        stages.remove(ALL_STAGES)
        stages.insert(0, ALL_STAGES)
    heads = list(headers) if headers is not None else [plots.metric_label(m) for m in metrics]
    digits = {m: decimals([v for r in rows if r.metric == m for v in (r.mean, r.upper)])
              for m in metrics}
    out = []
    for stage in stages:
        sub = [r for r in rows if r.stage == stage]
        cell = {(r.contestant, r.metric): r for r in sub}
        contestants = list(dict.fromkeys(r.contestant for r in sub))
        body = []
        for c in contestants:
            n_rows = episodes.get((c, stage), 0)
            tds = "".join(_cell_html(cell.get((c, m)), digits[m], n_rows) for m in metrics)
            body.append(f"<tr><td>{html.escape(c)}</td><td>{n_rows}</td>{tds}</tr>")
        title = "all stages" if stage == ALL_STAGES else stage
        th = "".join(f"<th>{html.escape(h)}</th>" for h in heads)
        out.append(f"<h3>{html.escape(title)}</h3>" if title else "")
        out.append(f'<div class="scroll"><table><tr><th>planner</th><th>n</th>{th}</tr>'
                   f"{''.join(body)}</table></div>")
    return "".join(out)


def _poster(video: Path) -> str:
    """The poster of a video as a ``data:image/png`` URI ("" if there is none).

    The episode's last frame (``final.png`` beside ``video.mp4``, ``final_3d.png`` beside
    ``video_3d.mp4``, written by ``run_episode``: it shows the whole trajectory and the
    outcome), else the video's first frame.
    """
    final = video.with_name(video.stem.replace("video", "final", 1) + ".png")
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


def _run_info(run_dir: Path, cols: dict[str, np.ndarray], contestants: Sequence[str],
              stages: Sequence[str]) -> str:
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
                         for k, v in data.items() if v is not None  # unset: e.g. worlds
                         and (not isinstance(v, dict | list) or len(json.dumps(v)) <= 300)]
        except (OSError, ValueError):
            pass
    info += [("episodes", str(len(cols["contestant"]))), ("contestants", ", ".join(contestants)),
             ("stages", ", ".join(stages))]
    if "outcome" in cols:
        outcomes, counts = np.unique(cols["outcome"].astype(str), return_counts=True)
        info.append(("outcomes", ", ".join(f"{o}: {n}" for o, n in
                                           zip(outcomes, counts, strict=True))))
    return "<h2>Run</h2><table>" + "".join(
        f'<tr><td class="l">{html.escape(k)}</td><td class="l info">{html.escape(v)}</td></tr>'
        for k, v in info) + "</table>"


def _note(params: Any) -> str:
    from arena.eval.metrics import MetricParams

    p = params if params is not None else MetricParams()
    rule = ("goal reached and fewer than 2 collisions (Arena 3.0 paper)"
            if p.success_rule == "arena" else "goal reached, collisions allowed")
    return (f"<p>Mean over episodes with its 95 % percentile-bootstrap interval [lower, upper] "
            f"({RESAMPLES} resamples, fixed seed); n: episodes. Cells over fewer than {MIN_N} "
            f"values show <span class=\"lown\">n=k†</span> and no interval (hatched bars in "
            f"the figures). Success: {rule}. Private zone: a person's body closer than "
            f"{p.private_zone_radius:g} m to the robot's body; personal-space radius "
            f"{p.personal_space_radius:g} m (Hall). Time to goal: successful episodes only. "
            "Time seen / facing: a person faced the robot / the robot faced a person.</p>")


def write_report(
    table: Any,
    run_dir: str | Path,
    out_html: str | Path,
    *,
    grids: Any = None,
    videos: Sequence[str | Path | tuple[str | Path, str]] = (),
    title: str = "Arena benchmark report",
    kinds: Sequence[plots.PlotKind] = ("bar", "box"),
    metrics: Sequence[str] | None = None,
    trajectory_episodes: int = 9,
    episode_figures: int = 200,
    workers: int = 1,
    figures: bool = True,
    params: Any = None,
) -> Path:
    """Write one self-contained HTML report (no external assets) and its figure files.

    Sections: run info; **results**: the headline tables (overall and per stage) and one
    grouped-bar figure per headline metric (mean, bootstrap interval, n; planners on the x
    axis, one colour per stage); **all metrics**: a collapsible table and, per other metric, a
    collapsible block with one figure, a panel per plot kind in ``kinds``; the social radar
    chart (fixed ranges); one trajectory figure per stage (see :func:`stage_trajectories`);
    the **episodes** table, each row linking to its episode's trajectory thumbnail (at most
    ``episode_figures``); the ``videos`` (MP4) embedded as base64, each with its last frame as
    poster.

    Args:
        table: the results table.
        run_dir: the run folder (records are resolved relative to it).
        out_html: the HTML file to write.
        grids: an :class:`~arena.maps.grid.OccupancyGrid` for every trajectory plot, or a mapping
            ``map_name -> grid``; ``None`` = rebuild each episode's map from its recorded config
            (blank background if that fails).
        videos: MP4 files to embed, each a path or a ``(path, caption)`` pair (default
            caption: the file's folder and name).
        title: page title.
        kinds: plot kinds drawn per non-headline metric.
        metrics: metrics to plot and tabulate; ``None`` = all numeric non-key columns.
        trajectory_episodes: most episodes per stage in the stage trajectory figure.
        episode_figures: most per-episode trajectory thumbnails ((stage, episode) pairs).
        workers: processes drawing the metric figures.
        figures: also save every figure as PDF and SVG under ``figures/`` beside the page.
        params: the metric parameters named in the notes (``None`` = defaults).

    Returns:
        The HTML path.
    """
    run_dir = Path(run_dir)
    out_html = Path(out_html)
    fig_dir = out_html.parent / "figures" if figures else None
    cols = plots.as_columns(table)
    names = list(metrics) if metrics is not None else plots.metric_columns(cols)
    contestants = plots.unique_in_order(cols["contestant"])
    stages = plots.unique_in_order(cols["stage"]) if "stage" in cols else [""]
    by_stage = len(stages) > 1
    parts = [f"<h1>{html.escape(title)}</h1>", _run_info(run_dir, cols, contestants, stages)]

    plotted = [m for m in names if np.isfinite(np.asarray(cols[m], np.float64)).any()]
    counts = episode_counts(cols)
    head = [(m, h) for m, h in HEADLINE_METRICS if m in plotted]
    parts.append("<h2>Results</h2>" + _note(params))
    if head:
        rows = summary_table(cols, [m for m, _ in head], overall=by_stage)
        parts.append(summary_html(rows, [m for m, _ in head], counts, [h for _, h in head]))
        images = _all_metric_images(table, [m for m, _ in head], ("bar",), by_stage, workers,
                                    fig_dir, "headline")
        parts.append('<div class="figs">' + "".join(t for tags in images for t in tags)
                     + "</div>")

    others = [m for m in plotted if m not in dict(head)]
    if plotted:
        rows = summary_table(cols, plotted, overall=by_stage)
        parts.append("<h2>All metrics</h2><details><summary>Table of every metric (mean "
                     "[interval])</summary>" + summary_html(rows, plotted, counts) + "</details>")
    images = _all_metric_images(table, others, kinds, by_stage, workers, fig_dir, "metric")
    for m, figs in zip(others, images, strict=True):
        parts.append(f"<details><summary>{html.escape(plots.metric_label(m))}</summary>"
                     f'<div class="figs">{"".join(figs)}</div></details>')

    social = [m for m in plots.SOCIAL_METRICS if m in cols and m in names]
    if social and len(contestants) > 1:
        parts.append('<h2>Social metrics</h2><div class="wide">' + _figure_tag(
            plots.plot_radar(table, social), "radar", figure_stem(fig_dir, "radar")) + "</div>")

    traj = []
    for s in stages:
        panels, note = stage_trajectories(cols, run_dir, s if "stage" in cols else None,
                                          grids=grids, max_episodes=trajectory_episodes)
        if panels:
            fig = plot_stage_trajectories(
                panels, contestants, title=f"Trajectories: {s}" if s else "Trajectories",
                note=note)
            traj.append(_figure_tag(fig, f"trajectories {s}",
                                    figure_stem(fig_dir, f"trajectories_{s or 'all'}")))
    if traj:
        parts.append(f'<h2>Trajectories</h2><div class="traj">{"".join(traj)}</div>')

    thumbs = episode_thumbnails(cols, run_dir, grids=grids, max_figures=episode_figures)
    parts.append("<h2>Episodes</h2>" + episode_section(cols, thumbs))

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
           + "\n".join(parts) + OPEN_TARGET_JS + "</body></html>\n")
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
        ``{"html": ..., "csv": ..., "tex": ..., "figures": ...}`` paths.
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
            if v.path_3d is not None:
                clips.append((v.path_3d, v.caption + " · 3-D" + note))
    clips.extend(videos)
    html_path = write_report(table, run, dest / "report.html", grids=grids, videos=clips,
                             workers=workers)
    return {"html": html_path, "csv": csv_path, "tex": tex_path, "figures": dest / "figures"}


__all__ = ["figure_stem", "main", "summary_html", "write_report"]

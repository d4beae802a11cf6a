"""The report's trajectories: episode maps, per-stage panels and the per-episode outcome table.

A run stores records, not maps: :func:`episode_grid` rebuilds the map an episode ran on from the
config in its record. :func:`stage_trajectories` gathers a stage's panels for
:func:`arena.eval.trajectory_plots.plot_stage_trajectories`. :func:`episode_section` writes the
HTML outcome table, one row per episode and contestant, whose rows link to one trajectory
thumbnail per (stage, episode) with every contestant's path on that episode's map.

Cost: the thumbnails dominate (record loading, map rebuilding, one small PNG each); they are
capped at ``max_figures`` (stage, episode) pairs, the rows past the cap are listed without link.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from arena.eval import plots
from arena.eval.record import EpisodeRecord
from arena.eval.trajectory_plots import (
    TrajectoryPanel,
    plot_stage_trajectories,
    trajectory_panels,
)


def episode_grid(record: EpisodeRecord) -> Any:
    """The map an episode ran on, obstacles burnt in, rebuilt from its recorded config.

    Episodes are pure functions of (config, seed, index), so redrawing episode
    ``record.meta.episode`` from ``record.meta.config`` gives the same map and obstacles,
    generated or not. ``None`` if the record has no config or it no longer loads.
    """
    from arena.config.schema import ExperimentConfig
    from arena.core.errors import ArenaError
    from arena.maps.raster import planning_grid
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
) -> tuple[list[TrajectoryPanel], str]:
    """The trajectory panels of one stage (see :func:`arena.eval.trajectory_panels`).

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
    return trajectory_panels(episodes, _episode_grids(grids, episodes),
                                   max_panels=max_episodes, total=len(total))


#: Columns of the outcome table: (results column, header, format); missing columns are left out.
#: The trajectory link follows ``episode``; the (long) seed comes last.
OUTCOME_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("stage", "stage", "{}"),
    ("episode", "episode", "{}"),
    ("contestant", "contestant", "{}"),
    ("outcome", "outcome", "{}"),
    ("time", "time [s]", "{:.1f}"),
    ("path_length", "path [m]", "{:.1f}"),
    ("collisions", "coll.", "{:.0f}"),
    ("collisions_static", "static", "{:.0f}"),
    ("collisions_pedestrian", "people", "{:.0f}"),
    ("collisions_robot", "robots", "{:.0f}"),
    ("time_in_private_zone", "priv. zone [s]", "{:.1f}"),
    ("min_distance_to_person", "min gap [m]", "{:.2f}"),
    ("seed", "seed", "{}"),
)
_TEXT = frozenset({"stage", "contestant", "outcome", "seed"})


def anchor(stage: str, episode: int) -> str:
    """The HTML id of a (stage, episode) trajectory thumbnail."""
    return f"ep-{stage}-{episode}" if stage else f"ep-{episode}"


def _cell(value: Any, form: str) -> str:
    if isinstance(value, float | np.floating) and not np.isfinite(value):
        return "–"
    try:
        return form.format(value)
    except (TypeError, ValueError):
        return str(value)


def episode_thumbnails(
    cols: Mapping[str, np.ndarray],
    run_dir: Path,
    *,
    grids: Any = None,
    max_figures: int = 200,
    dpi: int = 72,
) -> dict[tuple[str, int], str]:
    """One trajectory thumbnail per (stage, episode), every contestant's path on its map.

    Args:
        cols: the results table as columns (needs ``record`` and ``episode``).
        run_dir: the run folder (records are relative to it).
        grids: as in :func:`arena.eval.report.write_report`.
        max_figures: most thumbnails (the first pairs in table order).
        dpi: thumbnail resolution (72: about 260 px wide, 15-40 KiB each).

    Returns:
        ``(stage, episode) -> <img> tag`` (base64 PNG) for each drawn pair.
    """
    from arena.eval.io import load_record

    if "record" not in cols or "episode" not in cols or max_figures <= 0:
        return {}
    n = len(cols["contestant"])
    stage_col = cols["stage"] if "stage" in cols else np.full(n, "")
    contestants = plots.unique_in_order(cols["contestant"])
    pairs: dict[tuple[str, int], list[int]] = {}
    for i in range(n):
        key = (str(stage_col[i]), int(cols["episode"][i]))
        if key in pairs or len(pairs) < max_figures:
            pairs.setdefault(key, []).append(i)
    out: dict[tuple[str, int], str] = {}
    for (stage, ep), rows in pairs.items():
        paths: list[tuple[str, EpisodeRecord]] = []
        for i in rows:
            p = run_dir / str(cols["record"][i])
            if not cols["record"][i] or not p.is_file():
                continue
            try:
                paths.append((str(cols["contestant"][i]), load_record(p)))
            except Exception:
                continue
        if not paths:
            continue
        grid = _episode_grids(grids, {ep: paths})[ep]
        title = f"{stage} · episode {ep}" if stage else f"episode {ep}"
        fig = plot_stage_trajectories([TrajectoryPanel("", grid, tuple(paths))],
                                      [c for c in contestants if any(c == q for q, _ in paths)],
                                      title=title, panel_width=3.6)
        fig.set_dpi(dpi)
        data = base64.b64encode(plots.figure_png(fig)).decode("ascii")
        out[(stage, ep)] = (f'<img loading="lazy" alt="{html.escape(title)}" '
                            f'src="data:image/png;base64,{data}">')
    return out


def episode_section(
    cols: Mapping[str, np.ndarray], thumbnails: Mapping[tuple[str, int], str]
) -> str:
    """The HTML outcome table (a row per episode and contestant) and the thumbnails it links.

    Rows are ordered by stage, episode and contestant (an episode's planners side by side) and
    link to ``#<anchor>`` of their (stage, episode) thumbnail; a small script opens the
    collapsed section the thumbnail is in when the link is followed.
    """
    n = len(cols["contestant"])
    shown = [(k, h, f) for k, h, f in OUTCOME_COLUMNS if k in cols]
    ths = [f'<th class="l">{html.escape(h)}</th>' if k in _TEXT else f"<th>{html.escape(h)}</th>"
           for k, h, _ in shown]
    at = next((j + 1 for j, (k, _, _) in enumerate(shown) if k == "episode"), len(shown))
    ths.insert(at, "<th></th>")
    stage_col = cols["stage"] if "stage" in cols else np.full(n, "")
    # rows of one episode together, planners in order: compare them on the same episode
    stage_rank = {s: j for j, s in enumerate(plots.unique_in_order(stage_col))}
    who_rank = {c: j for j, c in enumerate(plots.unique_in_order(cols["contestant"]))}
    ep_col = cols["episode"] if "episode" in cols else np.zeros(n, int)
    order = sorted(range(n), key=lambda i: (stage_rank[str(stage_col[i])], int(ep_col[i]),
                                            who_rank[str(cols["contestant"][i])]))
    body = []
    for i in order:
        key = (str(stage_col[i]), int(cols["episode"][i])) if "episode" in cols else None
        tds = [f'<td class="l">{html.escape(_cell(cols[k][i], f))}</td>' if k in _TEXT
               else f"<td>{html.escape(_cell(cols[k][i], f))}</td>" for k, _, f in shown]
        tds.insert(at, f'<td class="l"><a href="#{anchor(*key)}">trajectory</a></td>'
                   if key is not None and key in thumbnails else "<td></td>")
        cls = str(cols["outcome"][i]) if "outcome" in cols else ""
        body.append(f'<tr class="o-{html.escape(cls)}">{"".join(tds)}</tr>')
    head = "".join(ths)
    missing = ""
    if "episode" in cols:
        pairs = {(str(stage_col[i]), int(cols["episode"][i])) for i in range(n)}
        if len(thumbnails) < len(pairs):
            missing = (f"<p>Trajectory thumbnails for the first {len(thumbnails)} of "
                       f"{len(pairs)} (stage, episode) pairs; raise <code>episode_figures</code>"
                       " for more.</p>")
    figs = "".join(f'<figure id="{html.escape(anchor(*k))}">{img}</figure>'
                   for k, img in thumbnails.items())
    return (f'<div class="scroll tall"><table class="episodes"><tr>{head}</tr>'
            f"{''.join(body)}</table></div>{missing}"
            + (f'<details id="episode-figures"><summary>Trajectory of each episode '
               f'({len(thumbnails)} figures)</summary><div class="thumbs">{figs}</div></details>'
               if figs else ""))


#: Opens the <details> around the element a followed link points to (pure inline script).
OPEN_TARGET_JS = (
    "<script>function openTarget(){var t=document.getElementById(location.hash.slice(1));"
    "for(var e=t;e;e=e.parentElement){if(e.tagName==='DETAILS'){e.open=true;}}"
    "if(t){t.scrollIntoView();}}window.addEventListener('hashchange',openTarget);"
    "window.addEventListener('load',openTarget);</script>"
)


__all__ = ["OUTCOME_COLUMNS", "anchor", "episode_grid", "episode_section", "episode_thumbnails",
           "stage_trajectories"]

"""Benchmark figures: per-metric distributions, a social radar chart and trajectory plots.

All figures are drawn with matplotlib's object API on the Agg canvas (no pyplot, no display,
safe in worker processes). Every function takes the per-episode results table (one row per
episode: ``contestant``, ``stage``, ``episode``, ``outcome``, float metric columns and
``record``) as a :class:`pyarrow.Table` or a mapping of equal-length arrays, returns the
:class:`~matplotlib.figure.Figure` and, given ``path``, also saves it as a PNG.

The plot kinds follow Arena's ``process_data`` (spec §4.3): ``bar`` (mean with 95 % CI error
bars), ``box``, ``violin`` and ``strip`` (jittered points), one per metric with the contestants
on the x axis, optionally split by stage.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray
from scipy import stats

from arena.eval.record import EpisodeRecord

FloatArray = NDArray[np.float64]
PlotKind = Literal["bar", "box", "violin", "strip"]
PLOT_KINDS: tuple[PlotKind, ...] = ("bar", "box", "violin", "strip")

#: Columns of the results table that are not metrics.
KEY_COLUMNS: frozenset[str] = frozenset({
    "contestant", "local_planner", "inter_planner", "stage", "episode", "seed", "map", "robot",
    "outcome", "record", "error", "wall_time", "time",
})

#: Direction of each known metric: ``True`` = higher is better, ``False`` = lower is better.
HIGHER_IS_BETTER: dict[str, bool] = {
    "success": True,
    "spl": True,
    "collisions": False,
    "timeout": False,
    "time_to_goal": False,
    "path_length": False,
    "path_length_ratio": False,
    "time_in_private_zone": False,
    "personal_space_compliance": True,
    "intimate_space_compliance": True,
    "min_distance_to_person": True,
    "group_space_intrusion": False,
    "induced_force": False,
    "time_looking_at_pedestrians": True,
    "time_seen_by_pedestrians": True,
    "clearance": True,
    "jerk": False,
    "roughness": False,
    "cf_displacement_mean": False,
    "cf_displacement_max": False,
    "cf_people_displaced": False,
}

#: The social metrics shown on the radar chart (those present in the table are used).
SOCIAL_METRICS: tuple[str, ...] = (
    "personal_space_compliance",
    "intimate_space_compliance",
    "min_distance_to_person",
    "time_in_private_zone",
    "group_space_intrusion",
    "induced_force",
    "time_seen_by_pedestrians",
    "cf_displacement_mean",
)

_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")


# -- table access ---------------------------------------------------------------------------------
def as_columns(table: Any) -> dict[str, NDArray[Any]]:
    """The results table as ``{column: numpy array}`` (accepts a pyarrow Table or a mapping)."""
    if isinstance(table, Mapping):
        cols = {str(k): np.asarray(v) for k, v in table.items()}
    else:
        cols = {name: table.column(name).to_numpy(zero_copy_only=False)
                for name in table.column_names}
    lengths = {len(v) for v in cols.values()}
    if len(lengths) > 1:
        raise ValueError(f"results columns differ in length: {sorted(lengths)}")
    for key in ("contestant", "stage"):
        if key in cols:
            cols[key] = cols[key].astype(str)
    return cols


def metric_columns(cols: Mapping[str, NDArray[Any]]) -> list[str]:
    """The float non-key columns of a results table (the metrics), in table order."""
    return [k for k, v in cols.items()
            if k not in KEY_COLUMNS and np.issubdtype(np.asarray(v).dtype, np.floating)]


def unique_in_order(values: NDArray[Any]) -> list[str]:
    """The distinct values of ``values`` in order of first appearance."""
    _, idx = np.unique(values, return_index=True)
    return [str(values[i]) for i in np.sort(idx)]


#: Metric-name words written as acronyms in labels ("spl" → "SPL", "cf_..." → "CF ...").
_ACRONYMS = {"spl": "SPL", "cf": "CF", "ttc": "TTC"}


def metric_label(name: str) -> str:
    """Axis label for a metric, e.g. ``"Time to goal [s]"`` (unit from the metric registry)."""
    unit = ""
    try:
        from arena.eval.metrics import METRICS

        if name in METRICS:
            unit = METRICS.get(name).unit
    except Exception:
        unit = ""
    words = [_ACRONYMS.get(w, w) for w in name.split("_")]
    text = " ".join(words)
    text = text[:1].upper() + text[1:]
    unit = {"m/s^2": "m/s²", "m/s^3": "m/s³"}.get(unit, unit)
    return f"{text} [{unit}]" if unit and unit not in ("1", "-") else (
        f"{text} [count]" if unit == "-" else text)


def mean_ci(values: FloatArray, confidence: float = 0.95) -> tuple[float, float, int]:
    """Mean, CI half-width ``t_{(1+c)/2, n-1} · s / √n`` and ``n`` of the finite values.

    The half-width is NaN for fewer than two values and 0 for constant samples.
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    n = int(v.size)
    if n == 0:
        return float("nan"), float("nan"), 0
    mean = float(v.mean())
    if n < 2:
        return mean, float("nan"), n
    half = float(stats.t.ppf(0.5 + confidence / 2.0, n - 1) * v.std(ddof=1) / np.sqrt(n))
    return mean, half, n


def _new_figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: str | Path | None) -> None:
    if path is not None:
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(p, format="png", dpi=fig.dpi)


# -- per-metric distribution plots -----------------------------------------------------------------
def plot_metric(
    table: Any,
    metric: str,
    kind: PlotKind = "box",
    *,
    by_stage: bool = False,
    path: str | Path | None = None,
    seed: int = 0,
) -> Figure:
    """One metric per contestant as a ``bar``, ``box``, ``violin`` or ``strip`` plot.

    Args:
        table: the results table.
        metric: metric column.
        kind: ``bar`` = mean with 95 % CI error bars; ``box``; ``violin``; ``strip`` = jittered
            points.
        by_stage: split each contestant's group into one coloured element per stage.
        path: save the figure as a PNG here.
        seed: seed of the strip-plot jitter (deterministic output).

    Returns:
        The figure.
    """
    if kind not in PLOT_KINDS:
        raise ValueError(f"unknown plot kind {kind!r}; choose from {PLOT_KINDS}")
    cols = as_columns(table)
    if metric not in cols:
        raise KeyError(f"metric {metric!r} not in the results table")
    values = np.asarray(cols[metric], dtype=np.float64)
    contestants = unique_in_order(cols["contestant"])
    stages = unique_in_order(cols["stage"]) if by_stage and "stage" in cols else [""]
    n_c, n_s = len(contestants), len(stages)
    width = 0.8 / n_s
    fig = _new_figure(max(4.0, 1.3 * n_c * max(1, n_s) ** 0.5 + 1.5), 3.6)
    ax = fig.add_subplot()
    rng = np.random.default_rng(seed)
    for j, stage in enumerate(stages):
        color = _COLORS[j % len(_COLORS)]
        mask_s = (cols["stage"] == stage) if stage else np.ones(values.size, bool)
        pos = np.arange(n_c) + (j - (n_s - 1) / 2.0) * width
        groups = [values[mask_s & (cols["contestant"] == c)] for c in contestants]
        groups = [g[np.isfinite(g)] for g in groups]
        label = stage or None
        if kind == "bar":
            mc = np.array([mean_ci(g)[:2] for g in groups]).reshape(-1, 2)
            ax.bar(pos, mc[:, 0], width * 0.9, yerr=np.nan_to_num(mc[:, 1]), capsize=4,
                   color=color, alpha=0.85, label=label, edgecolor="black", linewidth=0.6)
        elif kind == "box":
            bp = ax.boxplot([g if g.size else [np.nan] for g in groups], positions=pos,
                            widths=width * 0.8, patch_artist=True, manage_ticks=False)
            for patch in bp["boxes"]:
                patch.set_facecolor(color)
                patch.set_alpha(0.7)
            for med in bp["medians"]:
                med.set_color("black")
            if label:
                ax.bar([np.nan], [np.nan], color=color, alpha=0.7, label=label)
        elif kind == "violin":
            keep = [i for i, g in enumerate(groups) if g.size > 0]
            if keep:
                vp = ax.violinplot([_jitter_const(groups[i]) for i in keep], positions=pos[keep],
                                   widths=width * 0.9, showmeans=False, showmedians=True)
                for body in vp["bodies"]:  # type: ignore[attr-defined]
                    body.set_facecolor(color)
                    body.set_edgecolor("black")
                    body.set_alpha(0.6)
                for part in ("cbars", "cmins", "cmaxes", "cmedians"):
                    if part in vp:
                        vp[part].set_color("0.2")
                        vp[part].set_linewidth(1.0)
            if label:
                ax.bar([np.nan], [np.nan], color=color, alpha=0.6, label=label)
        else:  # strip
            for p, g in zip(pos, groups, strict=True):
                x = p + rng.uniform(-0.3, 0.3, g.size) * width
                ax.scatter(x, g, s=18, color=color, alpha=0.75, edgecolors="none",
                           label=label if p == pos[0] else None)
    ax.set_xticks(np.arange(n_c), contestants, rotation=20 if n_c > 4 else 0)
    ax.set_xlim(-0.6, n_c - 0.4)
    ax.set_xlabel("contestant")
    ax.set_ylabel(metric_label(metric))
    ax.set_title(f"{metric_label(metric).split(' [')[0]} ({kind})")
    ax.grid(axis="y", alpha=0.3)
    if n_s > 1:
        fig.legend(loc="outside lower center", ncols=min(n_s, 4), fontsize="small",
                   frameon=False)
    _save(fig, path)
    return fig


def _jitter_const(g: FloatArray) -> FloatArray:
    """A sample whose KDE exists: constant samples get a tiny spread (violinplot needs one)."""
    if g.size > 1 and np.ptp(g) > 0:
        return g
    base = g[0] if g.size else 0.0
    return base + np.array([-1e-9, 0.0, 1e-9]) * max(1.0, abs(float(base)))


# -- radar chart -----------------------------------------------------------------------------------
def radar_values(
    table: Any, metrics: Sequence[str] | None = None
) -> tuple[list[str], list[str], FloatArray]:
    """Per-contestant means of ``metrics`` normalised to [0, 1] across contestants (1 = best).

    For each metric ``m`` with contestant means ``x``: ``(x - min) / (max - min)`` where higher
    is better (:data:`HIGHER_IS_BETTER`, default higher), ``(max - x) / (max - min)`` where lower
    is better; a metric on which all contestants tie gets 1.0; NaN means stay NaN.

    Args:
        table: the results table.
        metrics: metric columns; ``None`` = the :data:`SOCIAL_METRICS` present in the table.

    Returns:
        ``(contestants, metrics, values)`` with ``values`` of shape ``(contestants, metrics)``.
    """
    cols = as_columns(table)
    names = list(metrics) if metrics is not None else [m for m in SOCIAL_METRICS if m in cols]
    if not names:
        raise ValueError("no metrics for the radar chart")
    contestants = unique_in_order(cols["contestant"])
    who = cols["contestant"]
    data = np.stack([np.asarray(cols[m], np.float64) for m in names], axis=1)  # (rows, M)
    member = who[None, :] == np.asarray(contestants)[:, None]  # (C, rows)
    finite = np.isfinite(data)
    counts = member.astype(np.float64) @ finite.astype(np.float64)  # (C, M)
    sums = member.astype(np.float64) @ np.where(finite, data, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.where(counts > 0, sums / np.where(counts > 0, counts, 1.0), np.nan)
        lo, hi = np.nanmin(means, axis=0), np.nanmax(means, axis=0)
        span = hi - lo
        norm = np.where(span > 0, (means - lo) / np.where(span > 0, span, 1.0), 1.0)
    higher = np.array([HIGHER_IS_BETTER.get(m, True) for m in names])
    norm = np.where(higher | (span <= 0), norm, 1.0 - norm)
    norm = np.where(np.isnan(means), np.nan, norm)
    return contestants, names, norm


def plot_radar(
    table: Any, metrics: Sequence[str] | None = None, *, path: str | Path | None = None
) -> Figure:
    """Radar chart of the normalised metrics of :func:`radar_values`, one polygon per contestant.

    The outer ring (1) is the best contestant on that axis, the centre (0) the worst.
    """
    contestants, names, norm = radar_values(table, metrics)
    m = len(names)
    angles = np.linspace(0.0, 2.0 * np.pi, m, endpoint=False)
    closed = np.append(angles, angles[0])
    fig = _new_figure(7.6, 6.0)
    ax = fig.add_subplot(projection="polar")
    for i, c in enumerate(contestants):
        r = np.nan_to_num(np.append(norm[i], norm[i, 0]))
        color = _COLORS[i % len(_COLORS)]
        ax.plot(closed, r, color=color, linewidth=1.8, marker="o", markersize=5, label=c)
        ax.fill(closed, r, color=color, alpha=0.15)
    labels = [n.replace("_", " ") + (" ↑" if HIGHER_IS_BETTER.get(n, True) else " ↓")
              for n in names]
    ax.set_xticks(angles, [_wrap(t) for t in labels], fontsize="small")
    ax.tick_params(axis="x", pad=6)
    ax.set_ylim(0.0, 1.05)
    ax.set_yticks([0.25, 0.5, 0.75, 1.0], ["", "0.5", "", "1"], fontsize="x-small")
    # A PolarAxes method; matplotlib's stubs type add_subplot's result as plain Axes.
    ax.set_rlabel_position(  # type: ignore[attr-defined]
        float(np.degrees(angles[1] / 2.0)) if m > 1 else 45.0
    )
    ax.set_title("Social metrics (normalised, 1 = best, 0 = worst)")
    fig.legend(loc="outside right upper", fontsize="small")
    _save(fig, path)
    return fig


def _wrap(text: str, width: int = 14) -> str:
    words, lines, cur = text.split(), [], ""
    for w in words:
        if cur and len(cur) + 1 + len(w) > width:
            lines.append(cur)
            cur = w
        else:
            cur = f"{cur} {w}".strip()
    lines.append(cur)
    return "\n".join(lines)


# -- trajectories ----------------------------------------------------------------------------------
def plot_trajectories(
    records: Sequence[EpisodeRecord],
    grid: Any | None = None,
    *,
    labels: Sequence[str] | None = None,
    title: str = "",
    path: str | Path | None = None,
) -> Figure:
    """Robot paths of ``records`` over the map (start ○, goal ★, collisions red ×).

    Pedestrians' paths are drawn faint grey. Without ``grid`` (an
    :class:`~arena.maps.grid.OccupancyGrid`) the background is blank and the axes fit the data.

    Args:
        records: episodes to draw (the same map).
        grid: occupancy grid drawn underneath (occupied black, unknown grey).
        labels: legend label per record (default ``"episode N (outcome)"``).
        title: figure title (default: the first record's map name).
        path: save the figure as a PNG here.
    """
    fig = _new_figure(6.4, 5.6)
    ax = fig.add_subplot()
    if grid is not None:
        data = np.asarray(grid.data)
        img = np.where(data == 100, 0.1, np.where(data < 0, 0.75, 1.0))
        x0, y0 = grid.origin
        h, w = data.shape
        ax.imshow(img, cmap="gray", vmin=0.0, vmax=1.0, origin="lower", interpolation="nearest",
                  extent=(x0, x0 + w * grid.resolution, y0, y0 + h * grid.resolution))
    collided_label = "collision"
    for i, rec in enumerate(records):
        color = _COLORS[i % len(_COLORS)]
        if rec.ped_row.size:
            order = np.lexsort((rec.ped_row, rec.ped_id))
            ids, pos = rec.ped_id[order], rec.ped_position[order]
            breaks = np.flatnonzero(np.diff(ids)) + 1
            for seg in np.split(pos, breaks):
                ax.plot(seg[:, 0], seg[:, 1], color="0.55", alpha=0.35, linewidth=0.8)
        xy = rec.pose[:, :2]
        lab = labels[i] if labels is not None else (
            f"episode {rec.meta.episode} ({rec.meta.outcome})")
        ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=1.8, label=lab)
        ax.plot(*rec.meta.start[:2], marker="o", color=color, markersize=8,
                markeredgecolor="black")
        ax.plot(*rec.meta.goal[:2], marker="*", color=color, markersize=13,
                markeredgecolor="black")
        hit = (rec.collision_wall | rec.collision_obstacle | rec.collision_pedestrian
               | rec.collision_robot)
        if np.any(hit):
            ax.scatter(xy[hit, 0], xy[hit, 1], marker="x", color="red", s=40, zorder=5,
                       linewidths=1.6, label=collided_label)
            collided_label = ""
    ax.plot([], [], color="0.55", alpha=0.5, label="pedestrians")
    ax.plot([], [], "o", color="white", markeredgecolor="black", label="start")
    ax.plot([], [], "*", color="white", markeredgecolor="black", markersize=11, label="goal")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    name = title or (records[0].meta.map_name if records else "")
    ax.set_title(f"Trajectories{': ' + name if name else ''}")
    handles, texts = ax.get_legend_handles_labels()
    keep = [k for k, t in enumerate(texts) if t and not t.startswith("_")]
    fig.legend([handles[k] for k in keep], [texts[k] for k in keep], fontsize="x-small",
               loc="outside right upper")
    _save(fig, path)
    return fig


# -- trajectory small multiples --------------------------------------------------------------------
@dataclass(frozen=True)
class TrajectoryPanel:
    """One panel of :func:`plot_stage_trajectories`: a map and the paths drawn on it.

    Attributes:
        title: panel title, e.g. ``"episode 3"``.
        grid: the :class:`~arena.maps.grid.OccupancyGrid` drawn underneath (``None`` = blank).
        paths: ``(contestant, record)`` pairs drawn on this map.
    """

    title: str
    grid: Any | None
    paths: tuple[tuple[str, EpisodeRecord], ...]


def contestant_colors(contestants: Sequence[str]) -> dict[str, str]:
    """Contestant → colour, the same assignment as the radar chart (order of appearance)."""
    return {c: _COLORS[i % len(_COLORS)] for i, c in enumerate(contestants)}


def trajectory_panels(
    episodes: Mapping[int, Sequence[tuple[str, EpisodeRecord]]],
    grids: Mapping[int, Any | None],
    *,
    max_panels: int = 9,
    total: int | None = None,
) -> tuple[list[TrajectoryPanel], str]:
    """Group a stage's episodes into the panels of :func:`plot_stage_trajectories`.

    If every episode has the same map (equal grids, or all ``None``) there is one panel with
    every episode's paths; otherwise one panel per episode on that episode's own map, the first
    ``max_panels`` episodes in index order.

    Args:
        episodes: episode index → ``(contestant, record)`` pairs of that episode.
        grids: episode index → its occupancy grid (``None`` = unknown, blank background).
        max_panels: most panels for per-episode maps.
        total: the stage's number of episodes if more exist than ``episodes`` holds (for the
            note).

    Returns:
        ``(panels, note)``; ``note`` says which episodes are shown, e.g.
        ``"episodes 0–8 of 12 shown, one map per episode"``.
    """
    order = sorted(episodes)
    if not order:
        return [], ""
    n_total = max(total or 0, len(order))
    first = grids.get(order[0])
    shared = all(_same_grid(grids.get(e), first) for e in order[1:])
    shown = order if shared else order[:max(1, max_panels)]
    which = (f"episodes {episode_ranges(shown)} of {n_total} shown" if len(shown) < n_total
             else f"{n_total} episode{'s' if n_total != 1 else ''}")
    if shared:
        paths = tuple(p for e in order for p in episodes[e])
        title = paths[0][1].meta.map_name if paths else ""
        return [TrajectoryPanel(title, first, paths)], f"{which}, one map"
    panels = [TrajectoryPanel(f"episode {e}", grids.get(e), tuple(episodes[e])) for e in shown]
    return panels, f"{which}, one map per episode"


def _same_grid(a: Any | None, b: Any | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return bool(a == b)


def episode_ranges(values: Sequence[int]) -> str:
    """Sorted indices as ranges: ``[0, 1, 2, 5]`` → ``"0–2, 5"``."""
    out: list[str] = []
    i = 0
    while i < len(values):
        j = i
        while j + 1 < len(values) and values[j + 1] == values[j] + 1:
            j += 1
        out.append(str(values[i]) if i == j else f"{values[i]}–{values[j]}")
        i = j + 1
    return ", ".join(out)


def _grid_image(grid: Any) -> tuple[FloatArray, tuple[float, float, float, float]]:
    data = np.asarray(grid.data)
    img = np.where(data == 100, 0.15, np.where(data < 0, 0.8, 1.0)).astype(np.float64)
    x0, y0 = (float(v) for v in grid.origin)
    h, w = data.shape
    res = float(grid.resolution)
    return img, (x0, x0 + w * res, y0, y0 + h * res)


def _panel_extent(panel: TrajectoryPanel) -> tuple[float, float, float, float]:
    """The panel's view: the map, grown to include every path, start and goal."""
    pts = [np.asarray(r.pose[:, :2], np.float64) for _, r in panel.paths]
    pts += [np.asarray([r.meta.start[:2], r.meta.goal[:2]], np.float64) for _, r in panel.paths]
    xy = np.concatenate(pts) if pts else np.zeros((0, 2))
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if panel.grid is not None:
        x0, x1, y0, y1 = _grid_image(panel.grid)[1]
        if xy.size:
            x0, x1 = min(x0, float(xy[:, 0].min())), max(x1, float(xy[:, 0].max()))
            y0, y1 = min(y0, float(xy[:, 1].min())), max(y1, float(xy[:, 1].max()))
        return x0, x1, y0, y1
    if not xy.size:
        return 0.0, 1.0, 0.0, 1.0
    pad = 0.05 * max(float(np.ptp(xy[:, 0])), float(np.ptp(xy[:, 1])), 1.0)
    return (float(xy[:, 0].min()) - pad, float(xy[:, 0].max()) + pad,
            float(xy[:, 1].min()) - pad, float(xy[:, 1].max()) + pad)


def plot_stage_trajectories(
    panels: Sequence[TrajectoryPanel],
    contestants: Sequence[str],
    *,
    title: str = "",
    note: str = "",
    path: str | Path | None = None,
) -> Figure:
    """Small multiples of robot paths: one panel per map, every contestant in its own colour.

    Each panel shows its map (occupied dark, unknown grey), each contestant's path in the colour
    of :func:`contestant_colors`, the episodes' starts (○) and goals (★) and red × where the
    record has a collision (wall, obstacle, pedestrian or robot). Panels share one legend below.

    Args:
        panels: the panels (see :func:`trajectory_panels`); at most 3 per row.
        contestants: every contestant in the run, in colour order (the legend lists them all).
        title: figure title, e.g. ``"Trajectories: stage canteen"``.
        note: smaller second title line, e.g. which episodes are shown.
        path: save the figure as a PNG here.

    Returns:
        The figure; ``fig.axes`` are the panels in order.
    """
    colors = contestant_colors(contestants)
    n = max(1, len(panels))
    ncols = min(3, n)
    nrows = -(-n // ncols)
    extents = [_panel_extent(p) for p in panels] or [(0.0, 1.0, 0.0, 1.0)]
    aspect = float(np.median([(e[3] - e[2]) / max(e[1] - e[0], 1e-9) for e in extents]))
    aspect = min(max(aspect, 0.2), 2.0)
    panel_w = (8.0 if aspect < 0.6 else 6.4) if n == 1 else 3.6
    width = panel_w * ncols + (0.3 if n > 1 else 0.0)
    height = panel_w * aspect * nrows + (1.1 if n == 1 else 1.2)
    fig = _new_figure(width, height)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    hit_any = False
    for k, ax in enumerate(axes.flat):
        if k >= len(panels):
            ax.set_visible(False)
            continue
        panel = panels[k]
        x0, x1, y0, y1 = extents[k]
        if panel.grid is not None:
            img, ext = _grid_image(panel.grid)
            ax.imshow(img, cmap="gray", vmin=0.0, vmax=1.0, origin="lower",
                      interpolation="nearest", extent=ext, zorder=0)
        starts: dict[tuple[float, float], tuple[float, float]] = {}
        for name, rec in panel.paths:
            color = colors.get(name, "0.3")
            xy = np.asarray(rec.pose[:, :2], np.float64)
            ax.plot(xy[:, 0], xy[:, 1], color=color, linewidth=1.6 if n == 1 else 1.4,
                    alpha=0.9, solid_capstyle="round", zorder=2)
            hit = (rec.collision_wall | rec.collision_obstacle | rec.collision_pedestrian
                   | rec.collision_robot)
            if np.any(hit):
                hit_any = True
                ax.scatter(xy[hit, 0], xy[hit, 1], marker="x", color="#e00000", s=36,
                           linewidths=1.5, zorder=5, gid="collision")
            s = (round(float(rec.meta.start[0]), 2), round(float(rec.meta.start[1]), 2))
            starts[s] = (float(rec.meta.goal[0]), float(rec.meta.goal[1]))
        for (sx, sy), (gx, gy) in starts.items():
            ax.plot(sx, sy, "o", color="white", markeredgecolor="black", markersize=7,
                    zorder=4)
            ax.plot(gx, gy, "*", color="gold", markeredgecolor="black", markersize=12,
                    zorder=4)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.tick_params(labelsize="small")
        if panel.title and n > 1:
            ax.set_title(panel.title, fontsize="medium")
        elif panel.title:  # one panel: its title joins the figure's second line
            note = f"{panel.title} · {note}" if note else panel.title
        if k // ncols == nrows - 1 or k + ncols >= len(panels):
            ax.set_xlabel("x [m]")
        if k % ncols == 0:
            ax.set_ylabel("y [m]")
    if title or note:
        fig.suptitle(title + (f"\n{note}" if note else ""), fontsize="large" if not note
                     else "medium")
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=colors[c], linewidth=2.2, label=c) for c in contestants]
    handles += [
        Line2D([], [], marker="o", linestyle="", color="white", markeredgecolor="black",
               markersize=7, label="start"),
        Line2D([], [], marker="*", linestyle="", color="gold", markeredgecolor="black",
               markersize=12, label="goal"),
    ]
    if hit_any:
        handles.append(Line2D([], [], marker="x", linestyle="", color="#e00000",
                              markersize=7, markeredgewidth=1.5, label="collision"))
    per_row = max(1, int(width / 1.2))  # legend entries that fit in one row
    fig.legend(handles=handles, loc="outside lower center",
               ncols=min(len(handles), per_row, -(-len(handles) // -(-len(handles) // per_row))),
               fontsize="medium", frameon=False)
    _save(fig, path)
    return fig


def figure_png(fig: Figure) -> bytes:
    """The figure encoded as PNG bytes."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=fig.dpi)
    return buf.getvalue()

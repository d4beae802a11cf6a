"""Trajectory figures: one episode set over its map, and per-stage small multiples.

Drawn with matplotlib's object API on the Agg canvas like :mod:`arena.eval.plots` (whose colours,
figure factory and PNG saving they share): robot paths in each contestant's colour, start ○,
goal ★, collisions as red ×, pedestrians' paths faint grey.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from arena.eval.plots import COLORS, new_figure, save_figure
from arena.eval.record import EpisodeRecord

FloatArray = NDArray[np.float64]

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
    fig = new_figure(6.4, 5.6)
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
        color = COLORS[i % len(COLORS)]
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
    save_figure(fig, path)
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
    return {c: COLORS[i % len(COLORS)] for i, c in enumerate(contestants)}


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
    panel_width: float | None = None,
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
        path: save the figure here (format from the suffix).
        panel_width: width of one panel in inches (default 6.4 to 8 for one panel, 3.6 for
            several); the per-episode thumbnails of the report use 3.6.

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
    panel_w = panel_width or ((8.0 if aspect < 0.6 else 6.4) if n == 1 else 3.6)
    width = panel_w * ncols + (0.3 if n > 1 else 0.0)
    height = panel_w * aspect * nrows + (1.1 if n == 1 else 1.2)
    fig = new_figure(width, height)
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
    save_figure(fig, path)
    return fig

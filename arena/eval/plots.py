"""Benchmark figures: per-metric bars with bootstrap intervals, distributions and a radar chart.

All figures are drawn with matplotlib's object API on the Agg canvas (no pyplot, no display,
safe in worker processes). Every function takes the per-episode results table (one row per
episode: ``contestant``, ``stage``, ``episode``, ``outcome``, numeric metric columns and
``record``) as a :class:`pyarrow.Table` or a mapping of equal-length arrays, returns the
:class:`~matplotlib.figure.Figure` and, given ``path``, also saves it (format from the suffix;
:func:`save_formats` writes PDF and SVG beside).

The plot kinds follow Arena's ``process_data`` (spec §4.3): ``bar`` (mean with its 95 %
percentile-bootstrap interval, :mod:`arena.eval.stats`; cells with fewer than
:data:`~arena.eval.stats.MIN_N` episodes hatched, without interval), ``box``, ``violin`` and
``strip`` (jittered points), one per metric with the contestants on the x axis, optionally
grouped by stage. Trajectory figures are in :mod:`arena.eval.trajectory_plots`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

from arena.eval.stats import MIN_N, Estimate, bootstrap_mean

FloatArray = NDArray[np.float64]
PlotKind = Literal["bar", "box", "violin", "strip"]
PLOT_KINDS: tuple[PlotKind, ...] = ("bar", "box", "violin", "strip")

#: Columns of the results table that are not metrics.
KEY_COLUMNS: frozenset[str] = frozenset({
    "contestant", "local_planner", "inter_planner", "stage", "episode", "seed", "map", "robot",
    "outcome", "record", "error", "wall_time", "time",
})

#: The paper's view (Arena 3.0 tables): metric and its short column header, in this order.
HEADLINE_METRICS: tuple[tuple[str, str], ...] = (
    ("success", "Success"),
    ("collisions", "Collisions"),
    ("time_to_goal", "Time to goal [s]"),
    ("path_length", "Path length [m]"),
    ("time_in_private_zone", "Private zone [s]"),
    ("time_seen_by_pedestrians", "Time seen [s]"),
    ("time_looking_at_pedestrians", "Time facing [s]"),
)

#: Direction of each known metric: ``True`` = higher is better, ``False`` = lower is better.
HIGHER_IS_BETTER: dict[str, bool] = {
    "success": True,
    "spl": True,
    "collisions": False,
    "collisions_static": False,
    "collisions_pedestrian": False,
    "collisions_robot": False,
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

#: Fixed axis range ``(worst-or-best low, high)`` of each radar metric, in its unit. Means are
#: placed linearly in this range and clipped to it, so a radar axis compares planners on one
#: absolute scale (0.963 vs 0.975 compliance stay 0.963 vs 0.975, not 0 vs 1). Rates (unit "1")
#: not listed here use [0, 1]. Times are per episode (the quick suite's episodes last <= 30 s);
#: a body gap of 2 m or more counts as fully clear.
RADAR_RANGES: dict[str, tuple[float, float]] = {
    "personal_space_compliance": (0.0, 1.0),
    "intimate_space_compliance": (0.0, 1.0),
    "cf_people_displaced": (0.0, 1.0),
    "min_distance_to_person": (0.0, 2.0),
    "time_in_private_zone": (0.0, 20.0),
    "group_space_intrusion": (0.0, 10.0),
    "induced_force": (0.0, 2.0),
    "time_seen_by_pedestrians": (0.0, 20.0),
    "time_looking_at_pedestrians": (0.0, 20.0),
    "cf_displacement_mean": (0.0, 1.0),
    "cf_displacement_max": (0.0, 2.0),
}

#: Colours in order of appearance (contestants in trajectories and the radar, stages in bars).
COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
          "#7f7f7f", "#bcbd22", "#17becf")
#: Hatch of bars over fewer than MIN_N episodes (drawn without interval).
LOW_N_HATCH = "///"


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
    """The numeric non-key columns of a results table (the metrics), in table order.

    Integer and boolean columns count (``collisions`` is an integer count); strings do not.
    """
    out = []
    for k, v in cols.items():
        dtype = np.asarray(v).dtype
        if k not in KEY_COLUMNS and (np.issubdtype(dtype, np.number)
                                     or np.issubdtype(dtype, np.bool_)):
            out.append(k)
    return out


def unique_in_order(values: NDArray[Any]) -> list[str]:
    """The distinct values of ``values`` in order of first appearance."""
    _, idx = np.unique(values, return_index=True)
    return [str(values[i]) for i in np.sort(idx)]


#: Metric-name words written as acronyms in labels ("spl" → "SPL", "cf_..." → "CF ...").
_ACRONYMS = {"spl": "SPL", "cf": "CF", "ttc": "TTC"}


def metric_unit(name: str) -> str:
    """The metric's unit from the registry ("" if unregistered)."""
    try:
        from arena.eval.metrics import METRICS

        return METRICS.get(name).unit if name in METRICS else ""
    except Exception:
        return ""


def metric_label(name: str) -> str:
    """Axis label for a metric, e.g. ``"Time to goal [s]"`` (unit from the metric registry)."""
    unit = metric_unit(name)
    words = [_ACRONYMS.get(w, w) for w in name.split("_")]
    text = " ".join(words)
    text = text[:1].upper() + text[1:]
    unit = {"m/s^2": "m/s²", "m/s^3": "m/s³"}.get(unit, unit)
    return f"{text} [{unit}]" if unit and unit not in ("1", "-") else (
        f"{text} [count]" if unit == "-" else text)


# -- figures and files -----------------------------------------------------------------------------
def new_figure(width: float, height: float) -> Figure:
    """A constrained-layout figure on the Agg canvas (``width`` × ``height`` inches, 100 dpi)."""
    fig = Figure(figsize=(width, height), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | Path | None) -> None:
    """Save ``fig`` to ``path`` (format from the suffix: png, pdf, svg); ``None``: nothing."""
    if path is not None:
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(p, format=p.suffix.lstrip(".").lower() or "png", dpi=fig.dpi)


def save_formats(fig: Figure, stem: str | Path, formats: Sequence[str] = ("pdf", "svg")
                 ) -> list[Path]:
    """Save ``fig`` as ``stem.<format>`` for each format (vector files for papers).

    SVG text stays text (``svg.fonttype: none``) so the files are small and editable; PDF
    embeds TrueType fonts (``pdf.fonttype: 42``), as journals ask.
    """
    import matplotlib as mpl

    paths = []
    with mpl.rc_context({"svg.fonttype": "none", "pdf.fonttype": 42,
                         "svg.hashsalt": "arena", "svg.id": None}):
        for fmt in formats:
            p = Path(f"{stem}.{fmt}")
            p.parent.mkdir(parents=True, exist_ok=True)
            meta = {"Date": None} if fmt == "svg" else {"CreationDate": None}
            fig.savefig(p, format=fmt, metadata=meta)
            paths.append(p)
    return paths


def figure_png(fig: Figure) -> bytes:
    """The figure encoded as PNG bytes."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=fig.dpi)
    return buf.getvalue()


# -- per-metric plots ------------------------------------------------------------------------------
def _groups(cols: Mapping[str, NDArray[Any]], metric: str, contestants: Sequence[str],
            stages: Sequence[str]) -> list[list[FloatArray]]:
    """The finite values of ``metric`` per stage (outer) and contestant (inner)."""
    values = np.asarray(cols[metric], dtype=np.float64)
    out = []
    for stage in stages:
        mask_s = (cols["stage"] == stage) if stage else np.ones(values.size, bool)
        groups = [values[mask_s & (cols["contestant"] == c)] for c in contestants]
        out.append([g[np.isfinite(g)] for g in groups])
    return out


def _bars(ax: Any, pos: FloatArray, groups: Sequence[FloatArray], width: float, color: str,
          label: str | None, show_n: bool) -> tuple[list[Estimate], bool]:
    """Mean bars with bootstrap-interval error bars; low-n cells hatched without interval.

    Returns the estimates and whether any cell was low-n.
    """
    est = [bootstrap_mean(g) for g in groups]
    mean = np.array([e.mean for e in est])
    ok = np.array([e.has_interval for e in est])
    low = np.array([e.low_n for e in est])
    err = np.zeros((2, len(est)))
    err[0, ok] = mean[ok] - np.array([e.lower for e in est])[ok]
    err[1, ok] = np.array([e.upper for e in est])[ok] - mean[ok]
    if (~low).any():
        ax.bar(pos[~low], mean[~low], width * 0.9, color=color, alpha=0.85, label=label,
               edgecolor="black", linewidth=0.6)
    if low.any():
        ax.bar(pos[low], mean[low], width * 0.9, color=color, alpha=0.35, hatch=LOW_N_HATCH,
               edgecolor="black", linewidth=0.6, label=None if (~low).any() else label)
    if ok.any():
        ax.errorbar(pos[ok], mean[ok], yerr=err[:, ok], fmt="none", ecolor="black",
                    elinewidth=1.0, capsize=3)
    for x, e in zip(pos, est, strict=True):
        if e.n == 0:
            continue
        top = e.upper if e.has_interval else e.mean
        if show_n or e.low_n:
            ax.annotate(f"n={e.n}" if e.low_n else f"{e.n}", (x, max(top, 0.0)),
                        xytext=(0, 2), textcoords="offset points", ha="center", va="bottom",
                        fontsize=6.5, color="0.25")
    return est, bool(low.any())


def plot_metric(
    table: Any,
    metric: str,
    kind: PlotKind | Sequence[PlotKind] = "box",
    *,
    by_stage: bool = False,
    path: str | Path | None = None,
    seed: int = 0,
    title: str | None = None,
) -> Figure:
    """One metric per contestant as a ``bar``, ``box``, ``violin`` or ``strip`` plot.

    ``bar``: the mean with its 95 % percentile-bootstrap interval (:func:`bootstrap_mean`).
    The number of episodes is shown: once in the subtitle if every bar has the same n, else
    above each bar. Bars over fewer than :data:`~arena.eval.stats.MIN_N` episodes are hatched,
    drawn without interval and labelled ``n=…``; the legend explains the hatch.

    Args:
        table: the results table.
        metric: metric column.
        kind: ``bar``, ``box``, ``violin`` or ``strip`` (jittered points), or several kinds:
            one panel each, side by side in one figure (one legend).
        by_stage: group each contestant's bars by stage (one colour per stage).
        path: save the figure here (format from the suffix).
        seed: seed of the strip-plot jitter (deterministic output).
        title: figure title (default: the metric's name, and the kind for a lone non-bar plot).

    Returns:
        The figure (``fig.axes``: one panel per kind).
    """
    kinds: tuple[PlotKind, ...] = (kind,) if isinstance(kind, str) else tuple(kind)
    for k in kinds:
        if k not in PLOT_KINDS:
            raise ValueError(f"unknown plot kind {k!r}; choose from {PLOT_KINDS}")
    cols = as_columns(table)
    if metric not in cols:
        raise KeyError(f"metric {metric!r} not in the results table")
    contestants = unique_in_order(cols["contestant"])
    stages = unique_in_order(cols["stage"]) if by_stage and "stage" in cols else [""]
    n_c, n_s = len(contestants), len(stages)
    # about 0.4 in per bar: 4 planners x 4 stages fit a 7 in (two-column page) figure
    panel_w = min(9.0, max(4.0, 0.4 * n_c * n_s + 1.6))
    fig = new_figure(panel_w if len(kinds) == 1 else min(14.0, 0.7 * panel_w * len(kinds)), 3.6)
    axes = fig.subplots(1, len(kinds), squeeze=False)[0]
    per_stage = _groups(cols, metric, contestants, stages)
    rng = np.random.default_rng(seed)
    low_any = False
    name = metric_label(metric).split(" [")[0]
    for ax, k in zip(axes, kinds, strict=True):
        low_any |= _draw_kind(ax, k, per_stage, contestants, stages, rng)
        ax.set_ylabel(metric_label(metric))
        sizes = {g.size for groups in per_stage for g in groups if g.size}
        sub = ""
        if k == "bar":
            sub = (f"mean, 95 % bootstrap interval; n = {next(iter(sizes))} episodes per bar"
                   if len(sizes) == 1 else "mean, 95 % bootstrap interval; n above each bar")
        elif len(sizes) == 1:
            sub = f"{k}, n = {next(iter(sizes))} episodes per group" if len(kinds) > 1 else (
                f"n = {next(iter(sizes))} episodes per group")
        elif len(kinds) > 1:
            sub = k
        if len(kinds) > 1:
            ax.set_title(sub, fontsize="medium")
        else:
            head = title if title is not None else (name if k == "bar" else f"{name} ({k})")
            ax.set_title(f"{head}\n{sub}" if sub else head, fontsize="medium")
        if k == "bar" and np.nanmin(np.asarray(cols[metric], np.float64), initial=0.0) >= 0:
            ax.set_ylim(bottom=0.0)  # non-negative metric: the axis starts at zero
            ax.set_ylim(top=ax.get_ylim()[1] * 1.08)  # room for the n labels above the bars
    if len(kinds) > 1:
        fig.suptitle(title if title is not None else name)
    handles, labels = axes[0].get_legend_handles_labels()
    if low_any:
        from matplotlib.patches import Patch

        handles.append(Patch(facecolor="white", edgecolor="black", hatch=LOW_N_HATCH))
        labels.append(f"n < {MIN_N}: no interval")
    if handles:
        fig.legend(handles, labels, loc="outside lower center",
                   ncols=min(len(handles), 5), fontsize="small", frameon=False)
    save_figure(fig, path)
    return fig


def _draw_kind(ax: Any, kind: PlotKind, per_stage: Sequence[Sequence[FloatArray]],
               contestants: Sequence[str], stages: Sequence[str],
               rng: np.random.Generator) -> bool:
    """Draw one panel of :func:`plot_metric`; True if a bar was low-n."""
    n_c, n_s = len(contestants), len(stages)
    width = 0.8 / n_s
    sizes = {g.size for groups in per_stage for g in groups if g.size}
    low_any = False
    for j, (stage, groups) in enumerate(zip(stages, per_stage, strict=True)):
        color = COLORS[j % len(COLORS)]
        pos: FloatArray = np.arange(n_c, dtype=np.float64) + (j - (n_s - 1) / 2.0) * width
        label = stage or None
        if kind == "bar":
            low_any |= _bars(ax, pos, groups, width, color, label, show_n=len(sizes) > 1)[1]
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
                for body in vp["bodies"]:
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
    ax.grid(axis="y", alpha=0.3)
    return low_any


def _jitter_const(g: FloatArray) -> FloatArray:
    """A sample whose KDE exists: constant samples get a tiny spread (violinplot needs one)."""
    if g.size > 1 and np.ptp(g) > 0:
        return g
    base = g[0] if g.size else 0.0
    return base + np.array([-1e-9, 0.0, 1e-9]) * max(1.0, abs(float(base)))


# -- radar chart -----------------------------------------------------------------------------------
def radar_range(metric: str) -> tuple[float, float]:
    """The fixed radar range of ``metric``: :data:`RADAR_RANGES`, else [0, 1] for rates.

    Raises:
        ValueError: for a metric with neither a listed range nor the unit "1".
    """
    if metric in RADAR_RANGES:
        return RADAR_RANGES[metric]
    if metric_unit(metric) == "1":
        return (0.0, 1.0)
    raise ValueError(f"radar metric {metric!r} has no fixed range: add it to "
                     "arena.eval.plots.RADAR_RANGES (rates with unit '1' use [0, 1])")


def radar_values(
    table: Any, metrics: Sequence[str] | None = None
) -> tuple[list[str], list[str], FloatArray]:
    """Per-contestant means of ``metrics`` placed on fixed ranges, 1 = best end of the range.

    For each metric with fixed range ``[lo, hi]`` (:func:`radar_range`) and contestant mean
    ``x``: ``(x - lo) / (hi - lo)`` where higher is better (:data:`HIGHER_IS_BETTER`, default
    higher), ``(hi - x) / (hi - lo)`` where lower is better, clipped to [0, 1]. The scale is
    absolute, so close means stay close (0.963 vs 0.975 compliance: 0.963 vs 0.975), unlike a
    min-max scaling across contestants. NaN means stay NaN.

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
    lo, hi = np.array([radar_range(m) for m in names], np.float64).T  # (M,) each
    norm = np.clip((means - lo) / (hi - lo), 0.0, 1.0)
    higher = np.array([HIGHER_IS_BETTER.get(m, True) for m in names])
    norm = np.where(higher, norm, 1.0 - norm)
    return contestants, names, np.where(np.isnan(means), np.nan, norm)


def plot_radar(
    table: Any, metrics: Sequence[str] | None = None, *, path: str | Path | None = None
) -> Figure:
    """Radar chart of :func:`radar_values`, one polygon per contestant.

    Each axis is its metric's fixed range (:func:`radar_range`, written under the axis name),
    oriented so that the outer ring (1) is the best end and the centre (0) the worst.
    """
    contestants, names, norm = radar_values(table, metrics)
    m = len(names)
    angles = np.linspace(0.0, 2.0 * np.pi, m, endpoint=False)
    closed = np.append(angles, angles[0])
    fig = new_figure(7.6, 6.0)
    ax = fig.add_subplot(projection="polar")
    for i, c in enumerate(contestants):
        r = np.nan_to_num(np.append(norm[i], norm[i, 0]))
        color = COLORS[i % len(COLORS)]
        ax.plot(closed, r, color=color, linewidth=1.8, marker="o", markersize=5, label=c)
        ax.fill(closed, r, color=color, alpha=0.15)
    labels = [_wrap(n.replace("_", " ") + (" ↑" if HIGHER_IS_BETTER.get(n, True) else " ↓"))
              + "\n" + _range_text(n) for n in names]
    ax.set_xticks(angles, labels, fontsize="small")
    ax.tick_params(axis="x", pad=6)
    ax.set_ylim(0.0, 1.05)
    ax.set_yticks([0.25, 0.5, 0.75, 1.0], ["", "0.5", "", "1"], fontsize="x-small")
    # A PolarAxes method; matplotlib's stubs type add_subplot's result as plain Axes.
    ax.set_rlabel_position(  # type: ignore[attr-defined]
        float(np.degrees(angles[1] / 2.0)) if m > 1 else 45.0
    )
    ax.set_title("Social metrics on fixed ranges (outer ring = best end of the range)",
                 fontsize="medium")
    fig.legend(loc="outside right upper", fontsize="small")
    save_figure(fig, path)
    return fig


def _range_text(metric: str) -> str:
    """``"[0, 2] m"``: a radar axis' fixed range with the unit."""
    lo, hi = radar_range(metric)
    unit = {"1": "", "-": "", "m/s^2": "m/s²"}.get(metric_unit(metric), metric_unit(metric))
    return f"[{lo:g}, {hi:g}]{' ' + unit if unit else ''}"


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

"""The frame legend: one row per element a frame shows, drawn the way the frame draws it.

A legend lists exactly what the frames (or the video) show: :func:`legend_items` reads it off
the states and overlays, :func:`legend_entries` checks and orders names given by hand. The
entries are the frame's elements (:data:`ELEMENTS`) and, under a ``people`` heading, the
pedestrians' social states (:data:`arena.render.style.AGENT_STATE_NAMES`).

The legend is sized by measuring its text with the same font machinery that draws it
(:func:`text_size`), so its box always holds its rows whatever the frame width; the
:class:`~arena.render.frames.FrameRenderer` reserves a column of that width right of the map.
Everything here works in display pixels (origin at the bottom left, ``y`` up).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.font_manager import FontProperties
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon, Rectangle
from matplotlib.transforms import IdentityTransform

from arena.core.errors import ConfigError
from arena.render import style

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.backends.backend_agg import RendererAgg

    from arena.render.frames import Overlay
    from arena.scene.state import SimState

DPI = 100.0
"""Frame resolution (pixels per inch): sizes in pixels are ``points · DPI / 72``."""

ELEMENTS: tuple[str, ...] = (
    "robot", "collision", "trail", "plan", "subgoal", "goal", "lidar", "detection", "track",
)
"""Legend names of the frame's elements, in legend order (social states follow)."""

LABELS: dict[str, str] = {
    "robot": "robot",
    "collision": "collision",
    "trail": "driven path",
    "plan": "global plan",
    "subgoal": "subgoal",
    "goal": "goal",
    "lidar": "lidar",
    "detection": "detection",
    "track": "track (id)",
}
"""Text of each element's row."""

PEOPLE_HEADING = "people"
# Layout in multiples of a row's height (the row height follows the font size).
_SYMBOL_ROWS = 1.8  # width of the symbol column
_PAD_ROWS = 0.35  # inner padding of the box
_GAP_ROWS = 0.3  # between a symbol and its text
_MARGIN_PX = 4.0  # between the box and the frame's edges


def legend_entries(names: Iterable[str] | bool) -> tuple[str, ...]:
    """Check legend entry names and put them in legend order (elements, then social states).

    Args:
        names: names from :data:`ELEMENTS` and social-state names; ``True`` means every entry
            (a full key), ``False`` none.

    Raises:
        ConfigError: an unknown name (the message lists the known ones).
    """
    known = ELEMENTS + style.AGENT_STATE_NAMES
    if isinstance(names, bool):
        return known if names else ()
    wanted = set()
    for name in names:
        if name not in known:
            raise ConfigError(f"legend: unknown entry {name!r}; known: {', '.join(known)}")
        wanted.add(name)
    return tuple(n for n in known if n in wanted)


def legend_items(
    states: Sequence[SimState],
    overlays: Iterable[Overlay | None] = (),
    *,
    lidar: bool = False,
    trails: bool = False,
) -> tuple[str, ...]:
    """The legend of frames of ``states`` drawn with ``overlays``: exactly what they show.

    Robots (and their trails and lidar) if any state has a robot, ``collision`` if any robot
    collides in some state, ``plan``, ``goal``, ``subgoal``, ``detection`` and ``track`` if
    some overlay holds one, and
    the social states the pedestrians take in ``states`` (codes without a name are not listed).

    Args:
        states: the snapshots the frames show.
        overlays: the overlays they are drawn with (``None`` entries are skipped).
        lidar: the renderer draws scans (``show_lidar`` and some robot has a lidar spec).
        trails: the renderer draws trails (they need two states or more).
    """
    items: list[str] = []
    if any(len(s.robots) for s in states):
        items.append("robot")
        if lidar:
            items.append("lidar")
        if trails and len(states) >= 2:
            items.append("trail")
    if any(np.any(s.collisions.any) for s in states):
        items.append("collision")
    for ov in overlays:
        if ov is None:
            continue
        if any(p is not None and np.shape(p)[0] >= 2 for p in ov.paths or ()):
            items.append("plan")
        if _any_finite(ov.goals):
            items.append("goal")
        if _any_finite(ov.subgoals):
            items.append("subgoal")
        if _any_finite(ov.detections):
            items.append("detection")
        if ov.tracks is not None and _any_finite(ov.tracks[1]):
            items.append("track")
    codes: set[int] = set()
    for s in states:
        codes.update(int(c) for c in np.unique(np.asarray(s.agents.states)))
    names = style.AGENT_STATE_NAMES
    items.extend(names[c] for c in sorted(codes) if 0 <= c < len(names))
    return legend_entries(items)


def _any_finite(points: Any) -> bool:
    if points is None:
        return False
    p = np.atleast_2d(np.asarray(points, dtype=np.float64))
    return p.size > 0 and bool(np.all(np.isfinite(p[:, :2]), axis=1).any())


@functools.cache
def _measurer() -> RendererAgg:
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(1, 1, DPI)


def text_size(text: str, size_pt: float, *, family: str | None = None) -> tuple[float, float]:
    """``(width, height)`` in pixels of one line of ``text`` as the frames draw it (no mathtext).

    Measured by Agg with the font matplotlib picks, so it matches the drawn text exactly.
    """
    prop = FontProperties(size=size_pt, family=family)
    w, h, _ = _measurer().get_text_width_height_descent(text, prop, ismath=False)
    return float(w), float(h)


def row_height(font_pt: float) -> float:
    """Pixels per legend row at ``font_pt``."""
    return 1.45 * font_pt * DPI / 72.0


def _rows(entries: Sequence[str]) -> list[tuple[str | None, str]]:
    """``(entry, text)`` per row: elements, then a ``people`` heading (entry ``None``), states."""
    rows: list[tuple[str | None, str]] = [(e, LABELS[e]) for e in entries if e in LABELS]
    states = [e for e in entries if e not in LABELS]
    if states:
        rows += [(None, PEOPLE_HEADING), *((e, e) for e in states)]
    return rows


def legend_size(entries: Sequence[str], font_pt: float) -> tuple[float, float]:
    """``(width, height)`` in pixels the legend takes, its margins to the frame edges included.

    ``(0, 0)`` for no entries.
    """
    if not entries:
        return 0.0, 0.0
    row = row_height(font_pt)
    text_w = max(text_size(label, font_pt)[0] for _, label in _rows(entries))
    width = text_w + (_SYMBOL_ROWS + _GAP_ROWS + 2 * _PAD_ROWS) * row + 2 * _MARGIN_PX
    height = len(_rows(entries)) * row + 2 * _PAD_ROWS * row + 2 * _MARGIN_PX
    return width, height


def draw_legend(
    ax: Axes, entries: Sequence[str], font_pt: float, frame_w: float
) -> tuple[float, float, float, float]:
    """Draw the legend box in the bottom-right corner of a ``frame_w`` pixels wide frame.

    Drawn with ``zorder`` below every moving artist, in display pixels.

    Returns:
        The box ``(x0, y0, x1, y1)`` in display pixels (``y`` up from the bottom).
    """
    width, height = legend_size(entries, font_pt)
    row = row_height(font_pt)
    x0, y0 = frame_w - width + _MARGIN_PX, _MARGIN_PX
    x1, y1 = frame_w - _MARGIN_PX, height - _MARGIN_PX
    ident = IdentityTransform()
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, transform=ident, facecolor=style.TEXT_BOX,
                           alpha=style.TEXT_BOX_ALPHA, edgecolor="none", zorder=1.5))
    sym_x = x0 + _PAD_ROWS * row + 0.5 * _SYMBOL_ROWS * row  # centre of the symbol column
    text_x = x0 + (_PAD_ROWS + _SYMBOL_ROWS + _GAP_ROWS) * row
    for k, (name, label) in enumerate(_rows(entries)):
        # on a pixel centre, so that thin lines (the plan) cover one pixel row fully
        y = np.floor(y1 - (_PAD_ROWS + k + 0.5) * row) + 0.5
        heading = name is None
        ax.text(sym_x - 0.5 * _SYMBOL_ROWS * row if heading else text_x, y, label,
                transform=ident, ha="left", va="center_baseline", fontsize=font_pt,
                fontstyle="italic" if heading else "normal", color=style.TEXT, zorder=1.7,
                parse_math=False)
        if name is not None:
            _draw_symbol(ax, name, sym_x, y, row)
    return x0, y0, x1, y1


def _pt(pixels: float) -> float:
    return pixels * 72.0 / DPI


def _draw_symbol(ax: Axes, name: str, cx: float, cy: float, row: float) -> None:
    """The symbol of entry ``name`` centred at ``(cx, cy)`` display pixels, styled as drawn."""
    ident = IdentityTransform()
    color = style.robot_color(0)
    half = 0.5 * _SYMBOL_ROWS * row - 2.0
    z = 1.6

    def line(xs: Sequence[float], ys: Sequence[float], **kw: Any) -> None:
        ax.add_line(Line2D(xs, ys, transform=ident, zorder=z, snap=False, **kw))

    if name in ("robot", "collision"):
        w, h = 0.9 * row, 0.6 * row
        hit = name == "collision"
        ax.add_patch(Rectangle(
            (cx - w / 2, cy - h / 2), w, h, transform=ident, facecolor=color,
            edgecolor=style.COLLISION if hit else style.shade(color, 0.55),
            linewidth=_pt(style.COLLISION_EDGE_PX if hit else style.ROBOT_EDGE_PX), zorder=z))
        line([cx, cx + w / 2], [cy, cy], color=style.HEADING,
             linewidth=_pt(style.HEADING_PX), solid_capstyle="round")
    elif name == "trail":
        line([cx - half, cx + half], [cy, cy], color=style.shade(color, style.TRAIL_TINT),
             linewidth=_pt(style.TRAIL_PX), solid_capstyle="round")
    elif name == "plan":
        line([cx - half, cx + half], [cy, cy], color=color, linewidth=_pt(style.PATH_PX),
             solid_capstyle="round")
    elif name == "subgoal":
        line([cx], [cy], marker="D", markersize=_pt(min(style.SUBGOAL_MARKER_PX, 0.7 * row)),
             markerfacecolor=style.shade(color, 1.35), markeredgecolor=style.HEADING,
             markeredgewidth=_pt(1.0), linestyle="none")
    elif name == "goal":
        line([cx], [cy], marker="o", markersize=_pt(min(style.GOAL_MARKER_PX, 0.8 * row)),
             markerfacecolor="none", markeredgecolor=color, markeredgewidth=_pt(2.6),
             linestyle="none")
    elif name == "lidar":
        # the scanned area as a faint fan from the sensor, its hits as dots along the far edge
        tip, far = cx - half, cx + half
        spread = 0.4 * row
        ax.add_patch(Polygon([(tip, cy), (far, cy - spread), (far, cy + spread)], closed=True,
                             transform=ident, facecolor=(*color, style.LIDAR_FAN_ALPHA),
                             edgecolor="none", zorder=z))
        line([far] * 3, [cy - spread, cy, cy + spread], marker="o",
             markersize=_pt(style.LIDAR_HIT_PX), markerfacecolor=style.shade(color, 0.8),
             markeredgewidth=0.0, linestyle="none")
    elif name == "detection":
        line([cx], [cy], marker="x", markersize=_pt(min(style.DETECTION_MARKER_PX, 0.7 * row)),
             markeredgecolor=style.DETECTION, markeredgewidth=_pt(2.0), linestyle="none")
    elif name == "track":
        line([cx], [cy], marker="o", markersize=_pt(min(style.TRACK_MARKER_PX, 0.8 * row)),
             markerfacecolor="none", markeredgecolor=style.TRACK_COLORS[0],
             markeredgewidth=_pt(2.0), linestyle="none")
    else:  # a social state: a pedestrian's disc in that state's colour
        code = style.AGENT_STATE_NAMES.index(name)
        line([cx], [cy], marker="o", markersize=_pt(0.7 * row),
             markerfacecolor=style.agent_state_color(code),
             markeredgecolor=style.agent_kind_color(0), markeredgewidth=_pt(style.AGENT_EDGE_PX),
             linestyle="none")

"""Where things go in a frame: its size, the map's scale and place, the text strip, the legend.

A frame is ``width_px`` wide. Its top holds a strip with the time line (left) and the title
(right, or on a second line where both do not fit); the legend takes a column at the right;
the map fills the rest at one scale on both axes, centred, and the frame is as tall as the map
needs, up to ``max_height_px``. Text is measured (:func:`arena.render.legend.text_size`), so no
title or legend is ever clipped at any width or map aspect ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arena.core.errors import ConfigError
from arena.maps.grid import UNKNOWN, OccupancyGrid
from arena.render.legend import DPI, legend_size, text_size
from arena.scene.state import StaticWorld

MAX_WIDTH_PX = 8000
"""Widest frame drawn (pixels): an 8K image; wider ones take gigabytes for nothing."""

KNOWN_MARGIN_M = 1.0
"""Unknown space shown around the mapped part of a map (m), so its outer walls keep a border."""

TITLE_FONT = 1.15
"""Title font size relative to the frame's base font (:func:`font_size`)."""
LEGEND_FONT = 0.9
"""Legend font size relative to the frame's base font."""
BOX_PAD = 0.3
"""Padding of the white box behind a text, a fraction of its font size (matplotlib's ``pad``)."""
# The longest usual time line (``run_episode``'s, with an outcome): the title shares the top
# line with it only where both fit.
_HUD_SAMPLE = "t = 000.0 s   step 0000   collision"


@dataclass(frozen=True)
class FrameLayout:
    """A frame's geometry.

    Attributes:
        width_px, height_px: frame size (pixels; the height is even, for video encoders).
        scale: pixels per metre on both axes.
        left_m, top_m: world ``x`` of the left edge and ``y`` of the top edge (m).
        strip_px: height of the text strip at the top (0 where there is none).
        legend_px: width of the legend column at the right (0 without a legend).
        title: the title as drawn (shortened with "…" where it would not fit).
        title_line: strip line of the title (0: beside the time line, 1: under it).
    """

    width_px: int
    height_px: int
    scale: float
    left_m: float
    top_m: float
    strip_px: float
    legend_px: float
    title: str
    title_line: int

    @property
    def font_pt(self) -> float:
        """The base font size (pt) of the frame's texts."""
        return font_size(self.width_px)

    def line_top_px(self, k: int) -> float:
        """Pixels from the frame's top to the top of strip line ``k``'s text."""
        pad = BOX_PAD * self.font_pt * TITLE_FONT * DPI / 72.0
        return 4.0 + pad + k * _strip_row(self.width_px)


def font_size(width_px: float) -> float:
    """Base font size (pt): readable at 400 px wide, not huge at 1600 px."""
    return float(np.clip(width_px / 75.0, 7.0, 16.0))


def frame_layout(
    world: StaticWorld,
    *,
    width_px: int,
    max_height_px: int | None = None,
    margin_m: float = 0.0,
    crop_unknown: bool = True,
    title: str = "",
    legend: tuple[str, ...] = (),
) -> FrameLayout:
    """Lay out a frame of ``world`` (see the module docstring and ``FrameRenderer``'s arguments).

    Raises:
        ConfigError: ``width_px`` or ``max_height_px`` outside ``[16, MAX_WIDTH_PX]``, a negative
            ``margin_m``, or a frame too narrow for its legend (over half its width).
    """
    if not 16 <= width_px <= MAX_WIDTH_PX:
        raise ConfigError(f"width_px must lie in [16, {MAX_WIDTH_PX}] pixels, got {width_px}")
    max_h = int(width_px) if max_height_px is None else int(max_height_px)
    if not 16 <= max_h <= MAX_WIDTH_PX:
        raise ConfigError(
            f"max_height_px must lie in [16, {MAX_WIDTH_PX}] pixels, got {max_height_px}"
        )
    if margin_m < 0:
        raise ConfigError(f"margin_m must be >= 0 m, got {margin_m}")
    # -- view: map (its mapped part) ∪ obstacles, padded
    xmin, ymin, xmax, ymax = known_bounds(world.grid) if crop_unknown else world.grid.bounds
    for ob in world.obstacles:
        poly = ob.polygon
        xmin, ymin = min(xmin, float(poly[:, 0].min())), min(ymin, float(poly[:, 1].min()))
        xmax, ymax = max(xmax, float(poly[:, 0].max())), max(ymax, float(poly[:, 1].max()))
    xmin, ymin, xmax, ymax = xmin - margin_m, ymin - margin_m, xmax + margin_m, ymax + margin_m
    # The legend gets its own column right of the map (it must never hide the map, e.g. the
    # goal at the end of a long corridor), measured from its text so nothing is clipped.
    legend_w, legend_h = legend_size(legend, font_size(width_px) * LEGEND_FONT)
    if legend_w > 0.5 * width_px:
        raise ConfigError(
            f"width_px {width_px} is too narrow for a legend of {len(legend)} entries "
            f"({legend_w:.0f} px wide); use width_px >= {math.ceil(2 * legend_w)}"
        )
    title, title_line = _fit_title(title, width_px)
    strip = 4.0 + (title_line + 1) * _strip_row(width_px) if (title or legend) else 0.0
    map_w = float(width_px) - legend_w  # the map area: left of the legend, under the strip
    scale = map_w / (xmax - xmin)
    if (ymax - ymin) * scale + strip > max_h:  # too tall: fit the height instead
        scale = max(max_h - strip, 8.0) / (ymax - ymin)
    height = max(2, math.ceil((ymax - ymin) * scale + strip - 1e-6), math.ceil(legend_h + strip))
    height += height % 2
    # the map centred in its area
    left = 0.5 * (xmin + xmax) - 0.5 * map_w / scale
    top = 0.5 * (ymin + ymax) + (strip + 0.5 * (height - strip)) / scale
    return FrameLayout(int(width_px), int(height), scale, left, top, strip, legend_w, title,
                       title_line)


def known_bounds(grid: OccupancyGrid) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` (m) of the cells that are not unknown, padded.

    The padding is :data:`KNOWN_MARGIN_M`, within the map; the whole map if every cell is unknown.
    """
    known = grid.data != UNKNOWN
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    if rows.size == 0:
        return grid.bounds
    (ox, oy), res = grid.origin, grid.resolution
    x0, y0, x1, y1 = grid.bounds
    return (
        max(x0, ox + cols[0] * res - KNOWN_MARGIN_M),
        max(y0, oy + rows[0] * res - KNOWN_MARGIN_M),
        min(x1, ox + (cols[-1] + 1) * res + KNOWN_MARGIN_M),
        min(y1, oy + (rows[-1] + 1) * res + KNOWN_MARGIN_M),
    )


def _strip_row(width_px: float) -> float:
    """Pixels per line of the strip above the map: a title box (the largest text) and a gap."""
    title_pt = TITLE_FONT * font_size(width_px)
    return (1.25 + 2 * BOX_PAD) * title_pt * DPI / 72.0 + 6.0


def _fit_title(title: str, width_px: int) -> tuple[str, int]:
    """The title as drawn (shortened to the frame width) and its strip line (0 or 1)."""
    if not title:
        return "", 0
    base = font_size(width_px)
    size = base * TITLE_FONT
    pad = 2 * BOX_PAD * size * DPI / 72.0
    title = _shorten(title, size, width_px - 16.0 - pad)
    hud = text_size(_HUD_SAMPLE, base, family="monospace")[0] + 2 * BOX_PAD * base * DPI / 72.0
    return title, 0 if text_size(title, size)[0] + pad + hud + 24.0 <= width_px else 1


def _shorten(text: str, size_pt: float, width: float) -> str:
    """``text``, cut and ended with "…" where needed so that it is at most ``width`` px wide."""
    if text_size(text, size_pt)[0] <= width:
        return text
    while len(text) > 1 and text_size(text + "\u2026", size_pt)[0] > width:
        text = text[:-1]
    return text.rstrip() + "\u2026"

"""The static map layers of a frame: the occupancy grid as an image, and the scale bar."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.patches import Rectangle
from numpy.typing import NDArray

from arena.maps.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from arena.render import style
from arena.render.legend import DPI

if TYPE_CHECKING:
    from matplotlib.axes import Axes

SCALE_STEPS = (0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0)
"""Scale bar lengths (m): the longest one up to a fifth of the frame's width is drawn."""


def map_image(
    grid: OccupancyGrid, scale: float
) -> tuple[NDArray[np.uint8], tuple[float, float, float, float]]:
    """The map as an RGBA image (row 0 at the origin) and its extent ``(l, r, b, t)`` (m).

    When several cells fall on one pixel, blocks of cells are pooled with priority
    occupied > unknown > free, so that one-cell walls never vanish in a zoomed-out frame.
    """
    data = grid.data
    factor = math.floor(1.0 / (scale * grid.resolution))
    # Priority codes: 0 padding (transparent), 1 free, 2 unknown, 3 occupied.
    prio = np.ones(data.shape, dtype=np.uint8)
    prio[data == UNKNOWN] = 2
    prio[data == OCCUPIED] = 3
    prio[(data != FREE) & (data != UNKNOWN) & (data != OCCUPIED)] = 2
    if factor >= 2:
        h, w = prio.shape
        hp, wp = -(-h // factor) * factor, -(-w // factor) * factor
        padded = np.zeros((hp, wp), dtype=np.uint8)
        padded[:h, :w] = prio
        prio = padded.reshape(hp // factor, factor, wp // factor, factor).max(axis=(1, 3))
        cell = grid.resolution * factor
    else:
        cell = grid.resolution
    lut = np.zeros((4, 4), dtype=np.uint8)
    lut[1, :3], lut[2, :3], lut[3, :3] = (
        style.to_uint8(style.FREE),
        style.to_uint8(style.UNKNOWN),
        style.to_uint8(style.OCCUPIED),
    )
    lut[1:, 3] = 255
    image = lut[prio]
    ox, oy = grid.origin
    extent = (ox, ox + prio.shape[1] * cell, oy, oy + prio.shape[0] * cell)
    return image, extent


def scale_bar_length(max_length_m: float) -> float | None:
    """The longest of :data:`SCALE_STEPS` up to ``max_length_m`` (m), or ``None``."""
    fits = [v for v in SCALE_STEPS if v <= max_length_m]
    return fits[-1] if fits else None


def scale_bar_height_px(font_pt: float) -> float:
    """Pixels from the bottom of a scale bar's area to the top of its box."""
    return 12.0 + 5.0 + 1.6 * font_pt * DPI / 72.0 + 6.0


def draw_scale_bar(
    ax: Axes, corner: tuple[float, float], length: float, scale: float, font_pt: float
) -> None:
    """A boxed black-and-white scale bar.

    Args:
        ax: the frame's axes (data coordinates in metres).
        corner: world point ``(x, y)`` (m) at the bottom left of the area the bar is placed in;
            its box starts 6 px right of and above it.
        length: the bar's length (m).
        scale: pixels per metre.
        font_pt: the label's font size (pt).
    """
    s = scale
    pad, bar_h = 12.0 / s, 5.0 / s
    fontsize = font_pt
    text_h = 1.6 * fontsize * DPI / 72.0 / s
    x0, y0 = corner[0] + pad, corner[1] + pad
    ax.add_patch(
        Rectangle(
            (x0 - 0.5 * pad, y0 - 0.5 * pad),
            length + pad,
            bar_h + text_h + pad,
            facecolor=style.TEXT_BOX,
            alpha=style.TEXT_BOX_ALPHA,
            edgecolor="none",
            zorder=20,
        )
    )
    # Half black, half white: the bar reads on both light and dark backgrounds.
    ax.add_patch(
        Rectangle(
            (x0, y0),
            length,
            bar_h,
            facecolor=style.TEXT,
            edgecolor=style.TEXT,
            linewidth=72.0 / DPI,  # one pixel
            zorder=21,
        )
    )
    ax.add_patch(
        Rectangle(
            (x0 + 0.5 * length, y0),
            0.5 * length,
            bar_h,
            facecolor="white",
            edgecolor=style.TEXT,
            linewidth=72.0 / DPI,  # one pixel
            zorder=22,
        )
    )
    label = f"{length:g} m"
    ax.text(
        x0 + 0.5 * length,
        y0 + bar_h + 2.0 / s,
        label,
        ha="center",
        va="bottom",
        fontsize=fontsize,
        color=style.TEXT,
        zorder=22,
    )

"""Colours and sizes of the top-down renderer, in one place.

Colours are RGB tuples of floats in ``[0, 1]`` so that tests can compare pixels against them
(:func:`to_uint8`). Everything a frame fills with a solid colour is opaque, so a pixel in the
middle of a shape has exactly that shape's colour whatever lies underneath.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

RGB = tuple[float, float, float]


def hex_rgb(code: str) -> RGB:
    """``"#rrggbb"`` → ``(r, g, b)`` floats in ``[0, 1]``."""
    code = code.lstrip("#")
    return (int(code[0:2], 16) / 255.0, int(code[2:4], 16) / 255.0, int(code[4:6], 16) / 255.0)


def to_uint8(color: RGB) -> NDArray[np.uint8]:
    """A float colour as the ``(3,)`` uint8 pixel value Agg writes for it."""
    return np.round(np.asarray(color, dtype=np.float64) * 255.0).astype(np.uint8)


# -- map ---------------------------------------------------------------------------------------
FREE: RGB = hex_rgb("#fbfbf8")
OCCUPIED: RGB = hex_rgb("#2b2d33")
UNKNOWN: RGB = hex_rgb("#a7a9ad")
# Outside the map (only visible where obstacles stick out of it).
BACKGROUND: RGB = hex_rgb("#d9dce1")

# -- static obstacles ---------------------------------------------------------------------------
OBSTACLE_FACE: RGB = hex_rgb("#b08456")
OBSTACLE_EDGE: RGB = hex_rgb("#5e4328")

# -- robots -------------------------------------------------------------------------------------
# One hue per robot index; red is kept out because it means "collision".
ROBOT_COLORS: tuple[RGB, ...] = tuple(
    hex_rgb(c) for c in ("#1f77b4", "#7b4fb3", "#0f9aa8", "#8c564b", "#d45fb0", "#6b7a10")
)
COLLISION: RGB = hex_rgb("#e3121b")
HEADING: RGB = hex_rgb("#10131a")

# -- pedestrians ----------------------------------------------------------------------------------
# Face colour by social-state code (AgentStates.states = arena.crowd.state.SocialState). Codes
# beyond the palette wrap around, so new crowd states always get some colour. Red stays
# reserved for robot collisions.
AGENT_STATE_COLORS: tuple[RGB, ...] = tuple(
    hex_rgb(c)
    for c in (
        "#9aa5b1",  # 0 idle
        "#f5a623",  # 1 walking
        "#e8575f",  # 2 running
        "#4fb34f",  # 3 interacting
        "#9b6bd6",  # 4 talking
        "#27c2c2",  # 5 phone
        "#ee2fc8",  # 6 panic
        "#c9b51a",  # 7
    )
)
# Legend labels, index = social-state code (must match arena.crowd.state.SocialState).
AGENT_STATE_NAMES: tuple[str, ...] = (
    "idle",
    "walking",
    "running",
    "interacting",
    "talking",
    "phone",
    "panic",
)
# Outline colour by kind code (AgentStates.kinds): 0 adult, 1 elder, 2 child.
AGENT_KIND_COLORS: tuple[RGB, ...] = tuple(
    hex_rgb(c) for c in ("#3a3a3a", "#6a3d9a", "#11806a", "#b35900")
)

# -- overlays -----------------------------------------------------------------------------------
# Perceived people (navigation.perception): detections as crosses, tracks as rings per id.
DETECTION: RGB = hex_rgb("#d81b60")
TRACK_COLORS: tuple[RGB, ...] = tuple(
    hex_rgb(c) for c in ("#ff7f0e", "#2ca02c", "#9467bd", "#17becf", "#bcbd22", "#e377c2",
                         "#393b79", "#637939", "#8c6d31", "#843c39")
)  # none of them a robot's colour
DETECTION_MARKER_PX = 9.0
TRACK_MARKER_PX = 20.0
TRACK_LABEL_OFFSET_PX = 8.0
MAX_TRACK_LABELS = 48
"""Most track ids labelled in one frame (a pool of text artists)."""
TEXT: RGB = hex_rgb("#111111")
TEXT_BOX: RGB = (1.0, 1.0, 1.0)
TEXT_BOX_ALPHA = 0.8
LIDAR_FAN_ALPHA = 0.12
# Trails are a light tint of the robot colour, so the (darker) planned path stands out on top.
TRAIL_TINT = 1.55

# -- sizes (in frame pixels; the renderer converts them to points) ----------------------------
ROBOT_EDGE_PX = 1.6
COLLISION_EDGE_PX = 3.2
AGENT_EDGE_PX = 1.4
HEADING_PX = 1.6
PATH_PX = 1.8
TRAIL_PX = 3.0
LIDAR_HIT_PX = 3.0
GOAL_MARKER_PX = 13.0
SUBGOAL_MARKER_PX = 8.0


def palette(
    colors: Sequence[RGB], codes: Sequence[int] | NDArray[np.integer]
) -> NDArray[np.float64]:
    """Colours for integer codes ``(n,)`` → ``(n, 3)``; codes wrap around the palette."""
    idx = np.asarray(codes, dtype=np.int64).reshape(-1) % len(colors)
    return np.asarray(colors, dtype=np.float64).reshape(-1, 3)[idx]


def robot_color(i: int) -> RGB:
    """The colour of robot ``i`` (footprint, lidar, path, goal)."""
    return ROBOT_COLORS[i % len(ROBOT_COLORS)]


def agent_state_color(code: int) -> RGB:
    """The face colour of a pedestrian in social state ``code``."""
    return AGENT_STATE_COLORS[code % len(AGENT_STATE_COLORS)]


def agent_kind_color(code: int) -> RGB:
    """The outline colour of a pedestrian of kind ``code``."""
    return AGENT_KIND_COLORS[code % len(AGENT_KIND_COLORS)]


def shade(color: RGB, factor: float) -> RGB:
    """Darken (``factor < 1``) or lighten towards white (``factor > 1``) a colour."""
    c = np.asarray(color, dtype=np.float64)
    out = c * factor if factor <= 1.0 else c + (1.0 - c) * min(factor - 1.0, 1.0)
    r, g, b = (float(v) for v in np.clip(out, 0.0, 1.0))
    return (r, g, b)

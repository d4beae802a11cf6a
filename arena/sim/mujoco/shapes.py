"""Obstacle models as primitives: the library's ``shape3d`` kind scaled to footprint and height.

Every builder fills exactly the footprint's bounding box ``[x0, x1] × [y0, y1]`` (model frame)
from the floor to ``height``, so the 3-D model and the 2-D footprint agree; only a tree's crown,
a sphere of ``crown_radius`` on top, reaches beyond its trunk's footprint.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from arena.maps.obstacles import Shape3D
from arena.sim.mujoco.scene import Geom

Extent = tuple[float, float, float, float]
"""``(x0, y0, x1, y1)``: the footprint's bounding box in the model frame (m)."""


def box(name: str, x0: float, x1: float, y0: float, y1: float, z0: float, z1: float,
        material: str) -> Geom:
    """An axis-aligned box spanning the given ranges (m)."""
    return Geom(name, "box", ((x1 - x0) / 2, (y1 - y0) / 2, (z1 - z0) / 2),
                ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2), material)


def cylinder(name: str, cx: float, cy: float, r: float, z0: float, z1: float,
             material: str) -> Geom:
    """An upright cylinder of radius ``r`` from ``z0`` to ``z1`` (m)."""
    return Geom(name, "cylinder", (r, (z1 - z0) / 2), (cx, cy, (z0 + z1) / 2), material)


def _slab(name: str, e: Extent, round_: bool, z0: float, z1: float, material: str) -> Geom:
    """The whole footprint as a slab: a disc for round models, else a box."""
    x0, y0, x1, y1 = e
    if round_:
        return cylinder(name, (x0 + x1) / 2, (y0 + y1) / 2, min(x1 - x0, y1 - y0) / 2, z0, z1,
                        material)
    return box(name, x0, x1, y0, y1, z0, z1, material)


def _legs(e: Extent, round_: bool, n: int, thick: float, z1: float,
          material: str) -> list[Geom]:
    """``n`` legs at the footprint's rim (round) or its four corners (else), floor to ``z1``."""
    x0, y0, x1, y1 = e
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if round_:
        r = min(x1 - x0, y1 - y0) / 2 - thick
        return [box(f"leg{k}", cx + r * math.cos(a) - thick, cx + r * math.cos(a) + thick,
                    cy + r * math.sin(a) - thick, cy + r * math.sin(a) + thick, 0.0, z1, material)
                for k, a in enumerate(2 * math.pi * (i + 0.5) / n for i in range(n))]
    t = 2 * thick
    return [box(f"leg{k}", x, x + t, y, y + t, 0.0, z1, material)
            for k, (x, y) in enumerate(((x0, y0), (x1 - t, y0), (x1 - t, y1 - t), (x0, y1 - t)))]


def _table(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    top = min(0.04, h / 4)
    return [_slab("top", e, round_, h - top, h, "wood"),
            *_legs(e, round_, s.legs if round_ else 4, 0.025, h - top, "metal")]


def _chair(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    seat = min(s.seat_height, 0.6 * h)
    back = 0.04 * (x1 - x0) / 0.45
    return [box("seat", x0, x1, y0, y1, seat - 0.04, seat, "wood"),
            *_legs(e, False, 4, 0.015, seat - 0.04, "metal"),
            box("back", x0, x0 + back, y0, y1, seat, h, "wood")]


def _shelf(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    t = 0.02
    parts = [box("side_l", x0, x1, y0, y0 + t, 0, h, "wood"),
             box("side_r", x0, x1, y1 - t, y1, 0, h, "wood"),
             box("back", x0, x0 + t, y0 + t, y1 - t, 0, h, "dark_wood")]
    for k in range(s.levels + 1):
        z = k * (h - t) / s.levels
        parts.append(box(f"board{k}", x0 + t, x1, y0 + t, y1 - t, z, z + t, "wood"))
    return parts


def _rack(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    u, beam = 0.08, 0.1
    parts = [box(f"upright{k}", x, x + u, y, y + u, 0, h, "steel_blue")
             for k, (x, y) in enumerate(((x0, y0), (x1 - u, y0), (x1 - u, y1 - u), (x0, y1 - u)))]
    for k in range(s.levels):
        z = (k + 1) * h / s.levels - beam
        parts += [box(f"beam{k}_f", x1 - u, x1, y0 + u, y1 - u, z, z + beam, "orange"),
                  box(f"beam{k}_b", x0, x0 + u, y0 + u, y1 - u, z, z + beam, "orange")]
        if k < s.levels - 1:  # a pallet with goods on each beam level below the top
            top = min(z + beam + 0.15 + 0.6 * h / s.levels, (k + 2) * h / s.levels - beam)
            parts.append(box(f"goods{k}", x0 + u, x1 - u, y0 + 2 * u, y1 - 2 * u, z + beam,
                             top, "box"))
    return parts


def _pallet(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    deck = 0.2 * h
    parts = [box("deck", x0, x1, y0, y1, h - deck, h, "wood")]
    w = 0.12 * (y1 - y0)
    for k, y in enumerate((y0, (y0 + y1 - w) / 2, y1 - w)):
        parts.append(box(f"runner{k}", x0, x1, y, y + w, 0, h - deck, "dark_wood"))
    return parts


def _pallet_jack(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    body_x = x1 - 0.3 * (x1 - x0)
    fork_w = 0.3 * (y1 - y0)
    parts = [box("fork_l", x0, body_x, y0, y0 + fork_w, 0, 0.08, "metal"),
             box("fork_r", x0, body_x, y1 - fork_w, y1, 0, 0.08, "metal"),
             box("body", body_x, x1, y0, y1, 0, min(0.5 * h, 0.9), "orange")]
    if s.mast:  # a stacker: two mast rails up to the full height behind the forks
        parts += [box("mast_l", body_x, body_x + 0.08, y0, y0 + 0.08, 0, h, "metal"),
                  box("mast_r", body_x, body_x + 0.08, y1 - 0.08, y1, 0, h, "metal")]
    else:  # a tiller handle standing on the body
        cx, cy = x1 - 0.05, (y0 + y1) / 2
        parts.append(cylinder("handle", cx, cy, 0.03, min(0.5 * h, 0.9), h, "plastic"))
    return parts


def _desk(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    t = 0.03
    return [box("top", x0, x1, y0, y1, h - t, h, "wood"),
            box("side_l", x0, x1, y0, y0 + t, 0, h - t, "dark_wood"),
            box("side_r", x0, x1, y1 - t, y1, 0, h - t, "dark_wood"),
            box("modesty", x0, x0 + t, y0 + t, y1 - t, 0.3 * h, h - t, "dark_wood")]


def _office_chair(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    cx, cy, r = (x0 + x1) / 2, (y0 + y1) / 2, min(x1 - x0, y1 - y0) / 2
    seat = min(s.seat_height, 0.6 * h)
    return [cylinder("base", cx, cy, r, 0, 0.06, "plastic"),
            cylinder("column", cx, cy, 0.03, 0.06, seat - 0.06, "metal"),
            cylinder("seat", cx, cy, 0.75 * r, seat - 0.06, seat, "fabric"),
            box("back", cx - 0.75 * r, cx - 0.65 * r, cy - 0.6 * r, cy + 0.6 * r, seat + 0.05, h,
                "fabric")]


def _panel(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    return [box("panel", x0, x1, y0, y1, 0, h - 0.03, "panel"),
            box("rail", x0, x1, y0, y1, h - 0.03, h, "metal")]


def _tree(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    x0, y0, x1, y1 = e
    cx, cy, r = (x0 + x1) / 2, (y0 + y1) / 2, min(x1 - x0, y1 - y0) / 2
    crown = min(s.crown_radius, h / 3)  # a round crown on the top third (or more) of the tree
    return [cylinder("trunk", cx, cy, r, 0, h - crown, "bark"),
            Geom("crown", "sphere", (crown,), (cx, cy, h - crown), "leaves")]


def _box(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    return [_slab("body", e, False, 0, h, "box")]


def _cylinder(s: Shape3D, e: Extent, round_: bool, h: float) -> list[Geom]:
    return [_slab("body", e, True, 0, h, "box")]


BUILDERS: dict[str, Callable[[Shape3D, Extent, bool, float], list[Geom]]] = {
    "box": _box, "cylinder": _cylinder, "table": _table, "chair": _chair, "shelf": _shelf,
    "rack": _rack, "pallet": _pallet, "pallet_jack": _pallet_jack, "desk": _desk,
    "office_chair": _office_chair, "panel": _panel, "tree": _tree,
}
"""``shape3d.kind`` -> builder ``(shape, extent, round, height) -> geoms`` (model frame)."""


def obstacle_geoms(shape: Shape3D, extent: Extent, round_: bool, height: float) -> list[Geom]:
    """The primitives of one obstacle in its model frame (m), names local to the obstacle."""
    return BUILDERS[shape.kind](shape, extent, round_, height)

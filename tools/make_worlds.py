"""Regenerate the worlds shipped in ``arena/worlds/`` (deterministic; run from the repo root).

    python tools/make_worlds.py

Each world is drawn here in metres and saved in ROS map_server format, so it loads exactly like
an Arena-Rosnav world folder (``<name>/map/map.yaml`` + image).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arena.maps.grid import OccupancyGrid
from arena.maps.io import save_map

OUT = Path(__file__).resolve().parent.parent / "arena" / "worlds"


class Canvas:
    """A boolean occupancy raster addressed in metres (origin at the lower-left corner)."""

    def __init__(self, width: float, height: float, res: float) -> None:
        self.res = res
        self.occ = np.zeros((round(height / res), round(width / res)), dtype=bool)

    def _idx(self, v: float) -> int:
        return round(v / self.res)

    def box(self, x0: float, y0: float, x1: float, y1: float, value: bool = True) -> None:
        """Fill the axis-aligned rectangle [x0, x1] × [y0, y1] (m)."""
        self.occ[self._idx(y0) : self._idx(y1), self._idx(x0) : self._idx(x1)] = value

    def hwall(self, x0: float, x1: float, y: float, t: float = 0.15) -> None:
        """Horizontal wall of thickness ``t`` (m) centred on ``y``."""
        self.box(x0, y - t / 2, x1, y + t / 2)

    def vwall(self, x: float, y0: float, y1: float, t: float = 0.15) -> None:
        """Vertical wall of thickness ``t`` (m) centred on ``x``."""
        self.box(x - t / 2, y0, x + t / 2, y1)

    def door(self, x0: float, y0: float, x1: float, y1: float) -> None:
        """Clear an opening."""
        self.box(x0, y0, x1, y1, value=False)

    def border(self, t: float = 0.2) -> None:
        """Outer walls."""
        h, w = self.occ.shape
        h_m, w_m = h * self.res, w * self.res
        self.box(0, 0, w_m, t)
        self.box(0, h_m - t, w_m, h_m)
        self.box(0, 0, t, h_m)
        self.box(w_m - t, 0, w_m, h_m)


def small_office() -> OccupancyGrid:
    """24 × 16 m office: a corridor, six offices, a lobby and an open hall with pillars."""
    c = Canvas(24.0, 16.0, 0.05)
    c.border()
    # Corridor between y = 6.5 and y = 9.0, offices below, open hall above.
    c.hwall(0, 24, 6.5)
    c.hwall(0, 9.0, 9.0)
    for x in (4.0, 8.0, 12.0, 16.0, 20.0):
        c.vwall(x, 0, 6.5)
    for x0 in (0.0, 4.0, 8.0, 12.0, 16.0, 20.0):
        c.door(x0 + 1.5, 6.3, x0 + 2.7, 6.7)  # 1.2 m office doors
    c.door(3.0, 8.8, 4.4, 9.2)  # lobby door to the corridor
    c.vwall(9.0, 9.0, 16.0)
    c.door(8.8, 11.5, 9.2, 13.0)  # lobby door to the hall
    for x, y in ((12.5, 11.5), (17.0, 11.5), (21.0, 12.5)):
        c.box(x - 0.3, y - 0.3, x + 0.3, y + 0.3)  # pillars in the hall
    c.box(1.0, 13.0, 6.0, 14.0)  # reception desk in the lobby
    return OccupancyGrid.from_occupied(c.occ, 0.05, (-12.0, -8.0))


def empty_room() -> OccupancyGrid:
    """A 10 × 10 m room with walls only."""
    c = Canvas(10.0, 10.0, 0.05)
    c.border(0.1)
    return OccupancyGrid.from_occupied(c.occ, 0.05, (0.0, 0.0))


WORLDS = {"small_office": small_office, "empty_room": empty_room}


def main() -> None:
    """Write every world."""
    for name, make in WORLDS.items():
        path = save_map(make(), OUT / name / "map" / "map.yaml", image_format="png")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()

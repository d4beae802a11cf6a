"""Regenerate the worlds shipped in ``arena/worlds/`` (deterministic; run from the repo root).

    python tools/make_worlds.py

Each world is drawn here in metres and saved in ROS map_server format, so it loads exactly like
an Arena-Rosnav world folder (``<name>/map/map.yaml`` + image).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from arena.maps.grid import OccupancyGrid
from arena.maps.io import save_map
from arena.tasks.scenario import validate_file

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


def corridor() -> OccupancyGrid:
    """30 × 8 m: a 3 m wide corridor with alcoves and two side rooms through doors."""
    c = Canvas(30.0, 8.0, 0.05)
    c.border()
    c.hwall(0, 30, 2.5)
    c.hwall(0, 30, 5.5)
    for x0 in (4.0, 13.0, 22.0):
        c.door(x0, 2.3, x0 + 1.2, 2.7)  # doors to the rooms below
    for x0 in (8.0, 18.0, 26.0):
        c.door(x0, 5.3, x0 + 2.0, 5.7)  # alcoves / exits above
    c.vwall(10.0, 0, 2.5)
    c.vwall(20.0, 0, 2.5)
    c.vwall(15.0, 5.5, 8.0)
    return OccupancyGrid.from_occupied(c.occ, 0.05, (-15.0, -4.0))


def hospital_floor() -> OccupancyGrid:
    """36 × 24 m ward: a central corridor, patient rooms both sides, a lobby and a nurse station."""
    c = Canvas(36.0, 24.0, 0.05)
    c.border()
    c.hwall(0, 36, 9.5)
    c.hwall(0, 28, 14.5)
    for x in (6.0, 12.0, 18.0, 24.0, 30.0):
        c.vwall(x, 0, 9.5)
    for x in (7.0, 14.0, 21.0, 28.0):
        c.vwall(x, 14.5, 24.0)
    for x0 in (2.0, 8.0, 14.0, 20.0, 26.0, 32.0):
        c.door(x0, 9.3, x0 + 1.4, 9.7)  # rooms below the corridor
    for x0 in (2.5, 9.5, 16.5, 23.5):
        c.door(x0, 14.3, x0 + 1.4, 14.7)  # rooms above
    c.door(28.0, 14.3, 35.8, 14.7)  # the lobby opens onto the corridor (outer wall kept)
    c.box(30.0, 18.5, 34.0, 19.3)  # nurse station counter
    return OccupancyGrid.from_occupied(c.occ, 0.05, (-18.0, -12.0))


def campus() -> OccupancyGrid:
    """50 × 40 m outdoor campus: four buildings, a fountain, low walls along paths."""
    c = Canvas(50.0, 40.0, 0.1)
    c.border()
    for x0, y0, x1, y1 in ((4, 4, 16, 14), (30, 4, 46, 12), (4, 26, 14, 36), (32, 24, 46, 36)):
        c.box(x0, y0, x1, y1)
    c.box(24.0, 18.5, 26.0, 20.5)  # fountain
    c.hwall(18.0, 24.0, 24.0, 0.4)
    c.hwall(29.0, 35.0, 15.0, 0.4)
    return OccupancyGrid.from_occupied(c.occ, 0.1, (-25.0, -20.0))


WORLDS = {
    "small_office": small_office,
    "empty_room": empty_room,
    "corridor": corridor,
    "hospital_floor": hospital_floor,
    "campus": campus,
}


def _ped(
    name: str, pos: tuple[float, float], waypoints: list[tuple[float, float]], **kw: object
) -> dict:
    return {
        "name": name,
        "pos": [pos[0], pos[1], 0.0],
        "type": kw.pop("type", "adult"),
        "model": "actor1",
        "waypoints": [[x, y, 0.0] for x, y in waypoints],
        "waypoint_mode": kw.pop("waypoint_mode", 0),
        **kw,
    }


# One default scenario per world, in Arena's scenario format (coordinates in metres).
SCENARIOS: dict[str, dict] = {
    "small_office": {
        "robots": [{"start": [-10.0, 3.5, 0.0], "goal": [-9.0, -6.0, -1.57]}],
        "obstacles": {
            "static": [{"name": "shelf_1", "model": "shelf", "pos": [2.0, 5.5, 0.0]}],
            "interactive": [],
            "dynamic": [
                _ped("visitor_1", (-6.0, 0.0), [(8.0, 0.0), (-6.0, 0.0)]),
                _ped("visitor_2", (6.0, -0.5), [(-8.0, -0.5), (6.0, -0.5)], type="elder"),
                _ped("worker_1", (4.0, 5.0), [(10.0, 6.0), (3.0, 6.5), (3.0, 2.0), (10.5, 2.0)]),
            ],
        },
        "map": "small_office",
    },
    "empty_room": {
        "robots": [{"start": [1.5, 1.5, 0.78], "goal": [8.5, 8.5, 0.78]}],
        "obstacles": {
            "static": [{"name": "box_1", "model": "cuboid", "pos": [6.5, 7.5, 0.4]}],
            "interactive": [],
            "dynamic": [
                _ped("p1", (2.0, 8.0), [(8.0, 2.0), (2.0, 8.0)]),
                _ped("p2", (8.0, 5.0), [(2.0, 5.0), (8.0, 5.0)]),
            ],
        },
        "map": "empty_room",
    },
    "corridor": {
        "robots": [{"start": [-13.5, 0.0, 0.0], "goal": [13.5, 0.0, 0.0]}],
        "obstacles": {
            "static": [],
            "interactive": [],
            "dynamic": [
                _ped("visitor_1", (12.0, 0.7), [(-12.0, 0.7), (12.0, 0.7)]),
                _ped("visitor_2", (10.0, -0.6), [(-12.0, -0.6), (10.0, -0.6)]),
                _ped("visitor_3", (-5.0, 0.0), [(6.0, 0.3), (-5.0, 0.0)], type="elder"),
                _ped(
                    "waiting_1",
                    (3.0, -0.9),
                    [(-9.0, -0.9)],
                    start_up_mode="trigger_zone",
                    trigger_zone_radius=3.0,
                ),
            ],
        },
        "map": "corridor",
    },
    "hospital_floor": {
        "robots": [{"start": [-15.0, 0.0, 0.0], "goal": [13.0, 5.5, 1.57]}],
        "obstacles": {
            "static": [{"name": "cart_1", "model": "cuboid", "pos": [-4.0, -1.95, 0.0]}],
            "interactive": [],
            "dynamic": [
                _ped("nurse_1", (-10.0, 0.5), [(10.0, 0.5), (-16.0, 0.5)]),
                _ped("doctor_1", (8.0, -0.5), [(-14.0, -0.5), (8.0, -0.5)]),
                _ped(
                    "patient_1",
                    (-15.0, -5.0),
                    [
                        (-15.0, -1.0),
                        (-9.0, -1.0),
                        (-9.0, -5.0),
                        (-9.0, -1.0),
                        (-15.0, -1.0),
                        (-15.0, -5.0),
                    ],
                    type="elder",
                    vmax=0.5,
                ),
                _ped("visitor_1", (17.0, 4.0), [(17.0, 10.0), (17.0, 4.0)]),
            ],
        },
        "map": "hospital_floor",
    },
    "campus": {
        "robots": [{"start": [-22.0, -0.0, 0.0], "goal": [22.0, 0.0, 0.0]}],
        "obstacles": {
            "static": [
                {"name": "tree_1", "model": "tree", "pos": [-5.0, -6.0, 0.0]},
                {"name": "tree_2", "model": "tree", "pos": [5.0, 6.0, 0.0]},
                {"name": "bench_1", "model": "cuboid", "pos": [0.0, -6.0, 0.0]},
            ],
            "interactive": [],
            "dynamic": [
                _ped("student_1", (-20.0, 2.5), [(20.0, 2.5), (-20.0, 2.5)]),
                _ped("student_2", (20.0, -2.5), [(-20.0, -2.5), (20.0, -2.5)]),
                _ped("student_3", (-7.9, 12.0), [(-7.9, -12.0), (-7.9, 12.0)]),
                _ped("student_4", (2.5, -14.0), [(2.5, 14.0), (2.5, -14.0)], type="elder"),
            ],
        },
        "map": "campus",
    },
}


def main() -> None:
    """Write every world and its default scenario (validated against the map)."""
    for name, make in WORLDS.items():
        path = save_map(make(), OUT / name / "map" / "map.yaml", image_format="png")
        scenario = OUT / name / "scenarios" / "default.json"
        scenario.parent.mkdir(parents=True, exist_ok=True)
        scenario.write_text(json.dumps(SCENARIOS[name], indent=2) + "\n")
        warnings = validate_file(scenario, path)  # raises if a position is off the map or in a wall
        print(f"wrote {path} and {scenario}" + (f" ({len(warnings)} warnings)" if warnings else ""))


if __name__ == "__main__":
    main()

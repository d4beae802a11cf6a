"""``arena maps generate --burn-obstacles``: placed obstacles drawn into map.png for map_server."""

from __future__ import annotations

import json

import numpy as np

from arena.core.geometry import points_in_polygon
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map
from arena.maps.raster import burn_obstacles
from arena.scene.state import Obstacle
from tests.cli_kit import run_cli


def test_burn_obstacles_marks_exactly_the_covered_cells():
    grid = OccupancyGrid.empty(4.0, 3.0, 0.1)
    # a 0.6 x 0.4 m box from x 1.05..1.65, y 1.05..1.45: edges in the middle of cells
    box = Obstacle("b", "cuboid", np.array([1.35, 1.25, 0.0]),
                   np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]))
    burnt = burn_obstacles(grid, [box])
    expected = np.zeros(grid.data.shape, dtype=bool)
    expected[10:15, 10:17] = True  # rows y 1.0..1.5, cols x 1.0..1.7: every cell it overlaps
    walls = grid.occupied.copy()  # the empty map's border
    assert not (walls & expected).any()
    np.testing.assert_array_equal(burnt.occupied, walls | expected)
    assert burn_obstacles(grid, []) is grid
    np.testing.assert_array_equal(grid.occupied, walls)  # the input grid is untouched


def _distance_to_polygon(xy: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """``(n,)`` distance (m) from points to a polygon's area (0 inside)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("nkd,kd->nk", xy[:, None] - a, ab) / np.sum(ab * ab, axis=1), 0, 1)
    d = np.linalg.norm(xy[:, None] - (a + t[..., None] * ab), axis=2).min(axis=1)
    return np.where(points_in_polygon(xy, poly), 0.0, d)


def test_generate_burns_the_placed_obstacles_into_map_png(monkeypatch, capsys, tmp_path):
    plain, burnt = tmp_path / "plain", tmp_path / "burnt"
    for folder, flag in ((plain, []), (burnt, ["--burn-obstacles"])):
        code, out, err = run_cli(monkeypatch, capsys, "maps", "generate", "canteen", "--seed",
                                 "3", "-o", str(folder), "--width-px", "200", *flag)
        assert code == 0, err
    assert "(burnt into map.png)" in out
    a = load_map(plain / "map" / "map.yaml")
    b = load_map(burnt / "map" / "map.yaml")
    static = json.loads((burnt / "map" / "obstacles.json").read_text())["obstacles"]["static"]
    assert static == json.loads((plain / "map" / "obstacles.json").read_text())["obstacles"][
        "static"]
    assert len(static) > 5
    # every obstacle's centre cell: free in the plain map, occupied in the burnt one
    centres = np.array([o["pos"][:2] for o in static])
    assert not a.is_occupied(centres).any()
    assert b.is_occupied(centres).all()
    # walls stay walls; the burnt map adds cells, all of them inside (or touching) a footprint
    assert np.all(b.occupied[a.occupied])
    added = b.occupied & ~a.occupied
    assert added.sum() > 0
    rows, cols = np.nonzero(added)
    xy = b.cell_to_world(np.stack([rows, cols], axis=1))
    from arena.core.rng import derive_rng
    from arena.maps.generators import MAP_GENERATORS

    result = MAP_GENERATORS.build({"type": "canteen"}).build(derive_rng(3, "map"))
    assert len(result.obstacles) == len(static)
    # an added cell overlaps a footprint: its centre is within half a cell diagonal of one
    d = np.min([_distance_to_polygon(xy, o.polygon) for o in result.obstacles], axis=0)
    assert np.all(d <= b.resolution / np.sqrt(2) + 1e-9)

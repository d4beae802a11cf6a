"""Height maps (bilinear lookup, checks, files) and the terrain course generator."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from arena.core.errors import MapError
from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import (
    HeightMap,
    TerrainCourseParams,
    load_terrain_world,
    save_terrain_world,
    terrain_course,
)


def test_height_map_is_bilinear_between_centres_and_clamped_outside():
    h = np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])  # row 0 at y = origin
    hm = HeightMap(h, 0.5, (1.0, 2.0))
    centres = np.array([[1.25, 2.25], [1.75, 2.75], [2.25, 2.25]])
    np.testing.assert_allclose(hm.at(centres), [0.0, 4.0, 2.0])
    # halfway between the four lower-left centres: their mean
    np.testing.assert_allclose(hm.at([1.5, 2.5]), (0 + 1 + 3 + 4) / 4)
    # beyond the outermost centres (and off the map) the edge value holds
    # (1.1, 2.6): left of the first column of centres, 0.7 of the way from row 0 to row 1
    np.testing.assert_allclose(hm.at([[0.0, 0.0], [10.0, 10.0], [1.1, 2.6]]), [0.0, 5.0, 2.1])
    assert hm.at(np.zeros((4, 3, 2))).shape == (4, 3)


def test_height_map_rejects_bad_input():
    with pytest.raises(MapError, match="heights must lie in"):
        HeightMap(np.array([[0.0, -0.1], [0.0, 0.0]]), 0.1)
    with pytest.raises(MapError, match="finite"):
        HeightMap(np.array([[0.0, np.nan], [0.0, 0.0]]), 0.1)
    with pytest.raises(MapError, match="2-D array"):
        HeightMap(np.zeros(5), 0.1)
    with pytest.raises(MapError, match="resolution"):
        HeightMap(np.zeros((3, 3)), 0.0)
    grid = OccupancyGrid.empty(2.0, 2.0, 0.1)
    with pytest.raises(MapError, match="covers"):
        HeightMap(np.zeros((10, 20)), 0.1).check_covers(grid)
    HeightMap.flat(grid, 0.2).check_covers(grid)


def test_height_map_file_round_trip_and_errors(tmp_path):
    hm = HeightMap(np.random.default_rng(0).uniform(0, 1, (7, 9)), 0.05, (-1.0, 3.0))
    back = HeightMap.load(hm.save(tmp_path / "h.npz"))
    np.testing.assert_array_equal(back.heights, hm.heights)
    assert (back.resolution, back.origin) == (hm.resolution, hm.origin)
    with pytest.raises(MapError, match="no height map file"):
        HeightMap.load(tmp_path / "missing.npz")
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(MapError, match="not a height map file"):
        HeightMap.load(tmp_path / "bad.npz")


def test_course_is_deterministic_given_the_seed_and_differs_across_seeds():
    a = terrain_course(None, np.random.default_rng(3))
    b = terrain_course(None, np.random.default_rng(3))
    c = terrain_course(None, np.random.default_rng(4))
    np.testing.assert_array_equal(a.heights.heights, b.heights.heights)
    np.testing.assert_array_equal(a.grid.data, b.grid.data)
    assert a.features == b.features
    assert not np.array_equal(a.heights.heights, c.heights.heights)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_course_has_its_parts_where_it_says(seed):
    p = TerrainCourseParams()
    w = terrain_course(p, np.random.default_rng(seed))
    hm, f = w.heights, w.features
    assert hm.shape == w.grid.data.shape and hm.origin == w.grid.origin

    def centre(name):
        x0, y0, x1, y1 = f[name]
        return np.array([(x0 + x1) / 2, (y0 + y1) / 2])

    assert hm.at(centre("plateau")) == pytest.approx(p.plateau_height)
    assert hm.at(centre("low_step")) == pytest.approx(p.low_step)
    assert hm.at(centre("high_step")) == pytest.approx(p.high_step)
    assert hm.at(centre("ramp")) == pytest.approx(p.plateau_height / 2, abs=0.03)
    # the ramp's slope along its fall line, measured between two points 1 m apart on it
    x0, y0, x1, y1 = f["ramp"]
    along_x = (x1 - x0) > (y1 - y0) + 1e-9 or (y1 - y0) < p.ramp_width - 1e-9
    c = centre("ramp")
    d = np.array([0.5, 0.0]) if along_x else np.array([0.0, 0.5])
    slope = abs(float(hm.at(c + d) - hm.at(c - d)))
    assert math.degrees(math.atan(slope)) == pytest.approx(p.ramp_slope_deg, abs=0.5)
    x0, y0, x1, y1 = f["rough"]
    inside = hm.heights[int(y0 / 0.1) + 2:int(y1 / 0.1) - 2, int(x0 / 0.1) + 2:int(x1 / 0.1) - 2]
    assert inside.std() == pytest.approx(p.rough_std, rel=0.25)
    # only the border is blocked in 2-D: height is no obstacle there
    assert w.grid.occupied[1:-1, 1:-1].sum() == 0


def test_course_refuses_a_map_too_small():
    with pytest.raises(MapError, match="does not fit"):
        terrain_course(TerrainCourseParams(width=6.0, height=6.0), np.random.default_rng(0))
    with pytest.raises(ValidationError, match="plateau_height"):
        TerrainCourseParams(plateau_height=-1.0)
    with pytest.raises(ValidationError, match="extra"):
        TerrainCourseParams(plateau=1.0)


def test_terrain_world_folder_round_trip(tmp_path):
    w = terrain_course(None, np.random.default_rng(0))
    save_terrain_world(w, tmp_path / "course")
    grid, hm = load_terrain_world(tmp_path / "course")
    np.testing.assert_array_equal(grid.data, w.grid.data)
    np.testing.assert_array_equal(hm.heights, w.heights.heights)

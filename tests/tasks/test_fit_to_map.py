"""The demo on a user's small map: goal distance and obstacle counts fit it, and say so."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import SamplingError
from arena.maps.grid import OccupancyGrid
from arena.tasks.generator import TaskGenerator
from arena.tasks.robot_modes.random import (
    _largest_region_diameter,
    fitting_goal_distance,
    free_extent,
)
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler

ROOM = ["map.type=empty", "map.width=8", "map.height=8", "output.video=false"]
"""An 8 m × 8 m room and otherwise the packaged demo (goal_distance 12 m)."""
LOWERED = re.compile(r"goal distance lowered from 12 m to ([0-9.]+) m: .* is ([0-9.]+) m across")


def _episodes(overrides: list[str], n: int = 3):
    cfg = load_config(None, overrides)
    gen = TaskGenerator.from_config(cfg)
    return [gen.episode(i) for i in range(n)]


def test_demo_defaults_fit_an_8_m_room_and_say_so():
    with pytest.warns(UserWarning, match=LOWERED) as record:
        episodes = _episodes(ROOM)
    said = [str(w.message) for w in record if LOWERED.search(str(w.message))]
    assert len(said) == 1, "one warning per map and run, not one per episode"
    lowered, across = (float(v) for v in LOWERED.search(said[0]).groups())
    # The largest free region is the room less the jackal's clearance (0.267 + 0.25 m) and the
    # walls: its diagonal lies between that of a 6 m and an 8 m square.
    assert 6.0 * np.sqrt(2) < across < 8.0 * np.sqrt(2)
    assert lowered == pytest.approx(np.floor((across / 2 - 0.05) * 10) / 10, abs=0.1)
    for ep in episodes:
        spawn = ep.robots[0]
        assert spawn.start.distance_to(spawn.goal) >= lowered
        assert not ep.grid.is_occupied(spawn.start.xy) and not ep.grid.is_occupied(spawn.goal.xy)
    # Deterministic: the same draws again.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        again = _episodes(ROOM)
    assert [e.robots[0].goal for e in again] == [e.robots[0].goal for e in episodes]


def test_a_map_that_fits_the_demo_distance_keeps_it_silently():
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        ep = _episodes(["map.type=empty", "map.width=20", "map.height=20"], n=1)[0]
    assert ep.robots[0].start.distance_to(ep.robots[0].goal) >= 12.0


def test_a_map_that_held_the_distance_before_gets_the_same_draws():
    """14 m room: 12 m is more than every start can have, less than some can: tried first."""
    room = ["map.type=empty", "map.width=14", "map.height=14"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        fitted = _episodes(room)
    strict = _episodes([*room, "task.robots.min_goal_distance=12"])
    assert [e.robots[0].goal for e in fitted] == [e.robots[0].goal for e in strict]
    assert [e.robots[0].start for e in fitted] == [e.robots[0].start for e in strict]


def test_an_explicit_min_goal_distance_that_cannot_fit_is_an_error():
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)  # and no "lowered" warning
        with pytest.raises(
            SamplingError,
            match=r"12 m apart.* largest free region is [0-9.]+ m across.*min_goal_distance",
        ):
            _episodes([*ROOM, "task.robots.min_goal_distance=12"], n=1)


def test_largest_region_diameter_is_the_farthest_pair_of_its_cells():
    rng = np.random.default_rng(3)
    for _ in range(5):
        mask = rng.random((40, 30)) < 0.6
        labels = components(mask)
        counts = np.bincount(labels.ravel())
        cells = np.argwhere(labels == int(np.argmax(counts[1:])) + 1)
        d = cells[:, None, :] - cells[None, :, :]
        brute = float(np.sqrt(np.max(np.sum(d * d, axis=-1))))
        assert _largest_region_diameter(mask) == pytest.approx(brute)
    line = np.zeros((5, 9), dtype=bool)
    line[2, 1:8] = True  # collinear cells: no hull, the ends of the line
    assert _largest_region_diameter(line) == pytest.approx(6.0)
    assert _largest_region_diameter(np.zeros((4, 4), dtype=bool)) == 0.0


def test_every_start_in_the_largest_region_has_a_goal_at_the_fitting_distance():
    rng = np.random.default_rng(7)
    occ = np.zeros((60, 60), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    for r, c in rng.integers(5, 50, size=(8, 2)):
        occ[r:r + 8, c:c + 3] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    world = WorldSampler(grid)
    clearance = 0.5
    fit = fitting_goal_distance(world, clearance)
    assert fit == pytest.approx(free_extent(world, clearance) / 2 - 0.1)
    labels = components(world.candidate_mask(clearance))
    counts = np.bincount(labels.ravel())
    cells = np.argwhere(labels == int(np.argmax(counts[1:])) + 1)
    xy = grid.cell_to_world(cells)
    farthest = np.sqrt(np.max(np.sum((xy[:, None] - xy[None]) ** 2, axis=-1), axis=1))
    assert np.all(farthest >= fit + grid.resolution - 1e-9)


FEWER = re.compile(r"task\.obstacles\.(static|dynamic): not all (4|12) (obstacles|pedestrians) fit")


def test_demo_obstacle_counts_fit_a_small_room_and_say_so():
    tiny = ["map.type=empty", "map.width=4", "map.height=4"]
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")  # (the goal distance's warning is recorded too)
        episodes = _episodes(tiny, n=4)
    said = sorted(FEWER.search(str(w.message)).group(1) for w in record
                  if FEWER.search(str(w.message)))
    assert said == ["dynamic", "static"], "one warning per kind, map and run"
    for ep in episodes:
        assert len(ep.obstacles) < 4 and 0 < len(ep.agents.positions) < 12
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        again = _episodes(tiny, n=4)
    assert [len(e.obstacles) for e in again] == [len(e.obstacles) for e in episodes]
    assert all(np.array_equal(a.agents.positions, b.agents.positions)
               for a, b in zip(again, episodes, strict=True))


def test_obstacle_counts_that_must_hold_are_an_error():
    tiny = ["map.type=empty", "map.width=4", "map.height=4", "task.obstacles.when_full=error"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the goal distance's
        with pytest.raises(SamplingError, match=r"task\.obstacles\.static: .*obstacles"):
            _episodes(tiny, n=1)
        with pytest.raises(SamplingError, match=r"cannot place 12 pedestrians"):
            _episodes([*tiny, "task.obstacles.static=0"], n=1)

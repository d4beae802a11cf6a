"""The worlds shipped in the package: maps load, scenarios are valid and walkable."""

import itertools

import numpy as np
import pytest

from arena.crowd.models.walker import WaypointWalker
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig
from arena.maps.io import load_map
from arena.maps.raster import polygon_mask
from arena.maps.sources import WORLDS_DIR, packaged_worlds, resolve_world
from arena.robots.presets import load_robot
from arena.sim.native2d import Native2DBackend
from arena.tasks.sampling import line_of_sight
from arena.tasks.scenario import load_scenario, validate_file
from arena.tasks.scenario_convert import scenario_episode

WORLDS = ("campus", "corridor", "empty_room", "hospital_floor", "small_office")


def test_every_world_is_packaged():
    assert set(WORLDS) <= set(packaged_worlds())


@pytest.mark.parametrize("name", WORLDS)
def test_world_scenario_is_valid_and_walkable(name):
    map_yaml = resolve_world(name)
    scenario_path = WORLDS_DIR / name / "scenarios" / "default.json"
    assert validate_file(scenario_path, map_yaml) == []
    grid = load_map(map_yaml)
    sc = load_scenario(scenario_path)
    ep = scenario_episode(sc, grid, [load_robot("jackal")], time_limit=60.0)
    # Every pedestrian leg is walkable: a straight line clear of walls and placed obstacles
    # by the body radius (people walk their routes without a planner).
    blocked = grid.occupied | polygon_mask(grid, [o.polygon for o in ep.obstacles])
    clear = grid.with_occupied(blocked).distance > 0.35
    a = ep.agents
    for i in range(len(a)):
        wps = a.waypoints[i, : a.num_waypoints[i]]
        legs = list(itertools.pairwise(np.vstack([a.positions[i], wps])))
        if a.waypoint_mode[i] == 1:  # random: any waypoint may follow any other
            legs += list(itertools.permutations(wps, 2))
        else:  # loop: back from the last waypoint to the first
            legs.append((wps[-1], wps[0]))
        for p, q in legs:
            assert line_of_sight(grid, clear, p, q), f"{name}: agent {i} leg {p} -> {q} blocked"
    # The robot's goal is reachable.
    from arena.maps.raster import planning_grid
    from arena.nav.global_planners.astar import AStarPlanner

    r = ep.robots[0]
    assert len(AStarPlanner().plan(planning_grid(ep).inflate(r.model.radius), r.start, r.goal)) > 1
    # A short run: people move, nobody enters a wall.
    backend = Native2DBackend()
    crowd = CrowdSimulator(WaypointWalker(), PedestrianConfig(social_states=False))
    s0 = backend.reset(ep, crowd, np.random.default_rng(0))
    for _ in range(50):
        s = backend.step(np.zeros((1, 3)), 0.1)
    moved = np.hypot(*(s.agents.positions - s0.agents.positions).T)
    assert np.any(moved > 1.0)
    assert not np.any(grid.is_occupied(s.agents.positions))

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.geometry import points_in_polygon
from arena.maps.io import load_map
from arena.maps.sources import WORLDS_DIR, resolve_world
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.robot_modes.zones import ZoneRobots
from arena.tasks.world import WorldSampler
from arena.tasks.zones import (
    default_zone_files,
    load_zone_scenario,
    load_zone_setup,
    load_zones,
    sample_in_zones,
)

HOSPITAL = {"type": "world", "name": "hospital_floor"}
HOSPITAL_ZONES = WORLDS_DIR / "hospital_floor" / "map" / "zones.yaml"
HOSPITAL_SCENARIO = WORLDS_DIR / "hospital_floor" / "zones" / "default.yaml"
ROOM = {"type": "empty", "width": 16.0, "height": 12.0}

# Two zones in the empty 16 x 12 m room: west and east, with a public strip in the middle.
ZONES = """
- label: West
  category: a
  polygon: [[1, 1], [5, 1], [5, 11], [1, 11]]
- label: East
  category: [b, c]
  polygon:
    - [[11, 1], [15, 1], [15, 5], [11, 5]]
    - [[11, 7], [15, 7], [15, 11], [11, 11]]
- label: Middle
  category: c
  polygon: [[7, 2], [9, 2], [9, 10]]
"""

SCENARIO = """
pedestrians:
  - name: walker
    type: human/elder
    model: [actor1, actor2]
    waypoints in: [a]
    number of waypoints: [1, 3]
    amount: [2, 4]
  - name: other
    type: child
    waypoints in: "*"
    number of waypoints: 2
    amount: 1
robots:
  - name: west robot
    waypoints in: [a]
  - name: east robot
    waypoints in: [b]
"""


def files(tmp_path, zones=ZONES, scenario=SCENARIO):
    z, s = tmp_path / "zones.yaml", tmp_path / "scenario.yaml"
    z.write_text(zones)
    s.write_text(scenario)
    return z, s


def gen(robots=None, obstacles=None, map_spec=HOSPITAL, seed=0, n_robots=1):
    cfg = TaskConfig.model_validate(
        {"robots": robots or {"type": "zones"}, "obstacles": obstacles or {"type": "zones"}}
    )
    return TaskGenerator(
        cfg, map_spec=map_spec, robots=[load_robot("burger")] * n_robots, seed=seed
    )


def inside(zmap, points, categories):
    return zmap.contains(np.asarray(points).reshape(-1, 2), categories)


# -- files -----------------------------------------------------------------------------------
def test_load_forms_and_normalised_keys(tmp_path):
    z, s = files(tmp_path)
    setup = load_zone_setup(z, s)
    assert setup.zones.categories == ["a", "b", "c"]
    east = setup.zones.zones[1]
    assert east.category == ["b", "c"] and len(east.polygons()) == 2
    assert [zone.label for zone in setup.zones.of("c")] == ["East", "Middle"]
    walker, other = setup.scenario.pedestrians
    assert walker.waypoints_in == ["a"] and walker.kind == 1
    assert walker.model == ["actor1", "actor2"]
    assert (walker.amount.min, walker.amount.max) == (2, 4)
    assert other.waypoints_in == "*" and other.kind == 2 and other.model == ["actor1"]
    assert (other.number_of_waypoints.min, other.number_of_waypoints.max) == (2, 2)
    assert [r.name for r in setup.scenario.robots] == ["west robot", "east robot"]


@pytest.mark.parametrize(
    ("which", "old", "new", "path", "match"),
    [
        ("scenario", "amount: 1", "amount: [3, 1]", "pedestrians[1].amount", "must not exceed"),
        ("scenario", "amount: 1", "amount: many", "pedestrians[1].amount", "many"),
        ("scenario", "type: child", "type: robot", "pedestrians[1].type", "unknown pedestrian"),
        ("scenario", "    amount: 1", "    amount: 1\n    speed: 2", "pedestrians[1].speed",
         "unknown key"),
        ("scenario", "waypoints in: [b]", "waypoints in: [x]", "robots[1].waypoints_in",
         "unknown zone category 'x'"),
        ("zones", "[[7, 2], [9, 2], [9, 10]]", "[[7, 2], [9, 2]]", "[2].polygon[0]",
         "at least 3"),
        ("zones", "[[7, 2], [9, 2], [9, 10]]", "[[7, 2], [8, 2], [9, 2]]", "[2].polygon",
         "no area"),
        ("zones", "label: West", "lable: West", "[0].label", "missing.*lable: unknown key"),
    ],
)
def test_errors_name_file_and_entry(tmp_path, which, old, new, path, match):
    text = {"zones": ZONES, "scenario": SCENARIO}[which]
    assert old in text
    z, s = files(tmp_path, **{which: text.replace(old, new)})
    with pytest.raises(ConfigError, match=match) as e:
        load_zone_setup(z, s)
    assert e.value.source == str(z if which == "zones" else s)
    assert e.value.path == path


def test_missing_files_say_what_was_looked_for(tmp_path):
    with pytest.raises(ConfigError, match="zones file not found") as e:
        load_zones(tmp_path / "zones.yaml")
    assert str(tmp_path / "zones.yaml") in str(e.value)
    with pytest.raises(ConfigError, match="zone scenario file not found"):
        load_zone_scenario(tmp_path / "nope.yaml")
    # The world default: a world without zone files.
    (tmp_path / "w" / "map").mkdir(parents=True)
    (tmp_path / "w" / "map" / "map.yaml").write_text(
        (WORLDS_DIR / "empty_room" / "map" / "map.yaml").read_text()
    )
    (tmp_path / "w" / "map" / "map.png").write_bytes(
        (WORLDS_DIR / "empty_room" / "map" / "map.png").read_bytes()
    )
    g = gen(map_spec={"type": "world", "name": str(tmp_path / "w")}, robots={"type": "random"})
    with pytest.raises(ConfigError, match="zones file not found") as e:
        g.episode(0)
    assert str(tmp_path / "w" / "map" / "zones.yaml") in str(e.value)


def test_a_map_without_world_needs_explicit_files():
    with pytest.raises(ConfigError, match=r"task\.obstacles\.zones"):
        gen(map_spec=ROOM, robots={"type": "random"}).episode(0)


def test_default_files_of_a_world():
    assert default_zone_files(HOSPITAL) == (HOSPITAL_ZONES, HOSPITAL_SCENARIO)
    assert default_zone_files(ROOM) is None


# -- hospital_floor --------------------------------------------------------------------------
def test_hospital_zones_load_and_every_polygon_has_room_for_a_pedestrian():
    setup = load_zone_setup(HOSPITAL_ZONES, HOSPITAL_SCENARIO)
    assert set(setup.zones.categories) == {"public", "staff", "patient"}
    labels = [z.label for z in setup.zones.zones]
    assert {"Lobby", "Reception", "Corridor", "Storage Room", "Patient Room 1"} <= set(labels)
    scenario = setup.scenario
    assert [(p.name, p.amount.min, p.amount.max) for p in scenario.pedestrians] == [
        ("visitor", 5, 5), ("janitor", 1, 1), ("nurse", 2, 2), ("doctor", 2, 2),
        ("patient", 5, 5),
    ]
    assert [(r.name, r.waypoints_in) for r in scenario.robots] == [
        ("cleaning robot", ["public", "staff"]), ("service robot", ["staff", "patient"]),
    ]
    world = WorldSampler(load_map(resolve_world("hospital_floor")))
    rng = np.random.default_rng(0)
    for zone in setup.zones.zones:
        for poly in zone.polygons():
            # Room for three pedestrians (0.35 m) and a robot with clearance (0.6 m).
            pts = world.sample(3, 0.35, rng, what=zone.label, polygon=poly, forbid=False)
            assert points_in_polygon(pts, poly).all()
            world.sample(1, 0.6, rng, what=zone.label, polygon=poly, forbid=False)


def test_sampled_points_lie_in_zones_of_the_allowed_categories():
    zmap = load_zones(HOSPITAL_ZONES)
    world = WorldSampler(load_map(resolve_world("hospital_floor")))
    rng = np.random.default_rng(3)
    for cats in (["patient"], ["public", "staff"], "*"):
        pts = np.array([
            sample_in_zones(world, zmap, cats, 0.35, rng, what="p", forbid=False)
            for _ in range(334)
        ])
        assert inside(zmap, pts, cats).all()
        assert (world.clearance(pts) >= 0.35 - 1e-9).all()
    # Every category gets used: patient points fall in several rooms.
    pts = np.array([
        sample_in_zones(world, zmap, ["patient"], 0.35, rng, what="p", forbid=False)
        for _ in range(60)
    ])
    rooms = {z.label for z in zmap.zones if points_in_polygon(pts, z.polygons()[0]).any()}
    assert len(rooms) >= 5


def test_hospital_episodes_via_task_generator():
    setup = load_zone_setup(HOSPITAL_ZONES, HOSPITAL_SCENARIO)
    zmap = setup.zones
    g = gen(n_robots=2)
    roles_seen = set()
    for i in range(6):
        ep = g.episode(i)
        assert len(ep.agents) == 15 and len(ep.obstacles) == 0
        a = ep.agents
        offset = 0
        for group in setup.scenario.pedestrians:
            n = group.amount.max
            rows = slice(offset, offset + n)
            offset += n
            assert (a.kinds[rows] == group.kind).all()
            nwp = a.num_waypoints[rows]
            assert ((nwp >= group.number_of_waypoints.min)
                    & (nwp <= group.number_of_waypoints.max)).all()
            assert inside(zmap, a.positions[rows], group.waypoints_in).all()
            for k, row in enumerate(range(rows.start, rows.stop)):
                wps = a.waypoints[row, : nwp[k]]
                assert inside(zmap, wps, group.waypoints_in).all(), group.name
        # Starts keep the body clearance from each other.
        d = np.hypot(*(a.positions[:, None] - a.positions[None]).transpose(2, 0, 1))
        assert d[np.triu_indices(len(a), 1)].min() >= 2 * 0.35 - 1e-9
        # Robots: start and goal in the zones of their role.
        ctx = g.runtime(ep).ctx
        roles = ZoneRobots().roles(ctx)
        for spawn, role in zip(ep.robots, roles, strict=True):
            roles_seen.add(role.name)
            both = np.array([spawn.start.xy, spawn.goal.xy])
            assert inside(zmap, both, role.waypoints_in).all()
            assert spawn.start.distance_to(spawn.goal) >= 2.0
    assert roles_seen == {"cleaning robot", "service robot"}


def test_robot_roles_and_next_goals_respect_categories(tmp_path):
    z, s = files(tmp_path)
    zmap = load_zones(z)
    params = {"zones": str(z), "scenario": str(s)}
    g = gen(robots={"type": "zones", **params}, obstacles={"type": "zones", **params},
            map_spec=ROOM, n_robots=3)
    west = east = 0
    for i in range(8):
        ep = g.episode(i)
        rt = g.runtime(ep)
        roles = rt.ctx.robot_mode.roles(rt.ctx)
        rng = np.random.default_rng(i)
        for k, (spawn, role) in enumerate(zip(ep.robots, roles, strict=True)):
            cats = role.waypoints_in
            west += role.name == "west robot"
            east += role.name == "east robot"
            pose = spawn.goal
            for _ in range(5):
                nxt = rt.ctx.robot_mode.next_goal(rt.ctx, k, pose, rng)
                assert nxt is not None
                assert inside(zmap, [spawn.start.xy, spawn.goal.xy, nxt.xy], cats).all()
                pose = nxt
        # Pedestrians: counts within ranges, kinds per group, points in allowed zones.
        kinds = ep.agents.kinds
        assert 2 <= np.sum(kinds == 1) <= 4 and np.sum(kinds == 2) == 1
        walkers = kinds == 1
        assert inside(zmap, ep.agents.positions[walkers], ["a"]).all()
        nwp = ep.agents.num_waypoints
        assert ((nwp[walkers] >= 1) & (nwp[walkers] <= 3)).all() and nwp[~walkers][0] == 2
        for row in np.flatnonzero(walkers):
            assert inside(zmap, ep.agents.waypoints[row, : nwp[row]], ["a"]).all()
    assert west and east


def test_deterministic_and_seed_dependent():
    a = [episode_digest(gen().episode(i)) for i in range(3)]
    b = [episode_digest(gen().episode(i)) for i in reversed(range(3))][::-1]
    c = [episode_digest(gen(seed=5).episode(i)) for i in range(3)]
    assert a == b and a != c


def test_zero_waypoints_stand_at_start(tmp_path):
    scenario = "pedestrians:\n  - {name: p, waypoints in: [a], number of waypoints: 0, amount: 2}\n"
    z, s = files(tmp_path, scenario=scenario)
    g = gen(robots={"type": "random", "min_goal_distance": 1.0},
            obstacles={"type": "zones", "zones": str(z), "scenario": str(s)}, map_spec=ROOM)
    a = g.episode(0).agents
    assert len(a) == 2 and (a.num_waypoints == 1).all()
    assert np.allclose(a.waypoints[:, 0], a.positions)


def test_robots_zones_needs_robot_roles(tmp_path):
    scenario = "pedestrians: []\n"
    z, s = files(tmp_path, scenario=scenario)
    params = {"zones": str(z), "scenario": str(s)}
    with pytest.raises(ConfigError, match="no robot roles"):
        gen(robots={"type": "zones", **params}, obstacles={"type": "zones", **params},
            map_spec=ROOM).episode(0)

"""``fast_social_force``: the batched env's crowd as an ordinary crowd model and driver."""

from __future__ import annotations

import csv
import itertools
import warnings

import numpy as np
import pytest
from matplotlib.path import Path as PolygonPath
from scipy.spatial import cKDTree

from arena.config.loader import load_config
from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.crowd.driver import build_driver
from arena.crowd.models.fast_social_force.model import (
    FastSocialForceDriver,
    FastSocialForceModel,
    warn_once,
)
from arena.crowd.models.fast_social_force.params import FastSocialForceParams
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig
from arena.crowd.state import SocialState
from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.episode import WAYPOINT_LOOP, WAYPOINT_RANDOM, AgentSpawn, Episode, RobotSpawn
from arena.scene.state import AgentStates, Obstacle, RobotStates, StaticWorld
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from tests.cli_kit import run_cli

DT = 0.1


def _robots(xy: list[tuple[float, float]], radii: list[float]) -> RobotStates:
    """Robots standing at ``xy`` (m) with circumscribed radii ``radii`` (m)."""
    r = len(xy)
    poses = np.zeros((r, 3))
    poses[:, :2] = xy
    return RobotStates(
        tuple(f"r{k}" for k in range(r)), ("burger",) * r, poses, np.zeros((r, 3)),
        np.zeros((r, 3)), np.array(radii, dtype=np.float64), (None,) * r, (np.zeros(0),) * r,
    )


def _spawn(pos: np.ndarray, wps: np.ndarray, mode: int = WAYPOINT_LOOP,
           vmax: float = 1.2) -> AgentSpawn:
    n = pos.shape[0]
    return AgentSpawn(
        positions=pos, radii=np.full(n, 0.3), vmax=np.full(n, vmax), waypoints=wps,
        num_waypoints=np.full(n, wps.shape[1], np.int64), waypoint_mode=np.full(n, mode),
        kinds=np.zeros(n, np.int64),
    )


def _room(size: float = 20.0) -> OccupancyGrid:
    """An empty square room of ``size`` m with 0.1 m walls, 5 cm cells."""
    cells = round(size / 0.05)
    return OccupancyGrid.from_occupied(
        np.pad(np.zeros((cells - 4, cells - 4), bool), 2, constant_values=True), 0.05
    )


@pytest.fixture(scope="module")
def office_episode() -> Episode:
    """small_office with 6 random obstacles and 20 pedestrians on 4-waypoint loops."""
    task = TaskConfig(obstacles={"type": "random", "static": 6, "dynamic": 20})
    gen = TaskGenerator(task, map_spec={"type": "world", "name": "small_office"},
                        robots=[load_robot("jackal")], seed=2)
    return gen.episode(0)


def _run(driver: FastSocialForceDriver | CrowdSimulator, ep: Episode, robots: RobotStates,
         steps: int, seed: int = 0) -> list[AgentStates]:
    world = StaticWorld.build(ep.grid, ep.obstacles)
    out = [driver.reset(ep.agents, world, np.random.default_rng(seed))]
    out += [driver.step(robots, DT) for _ in range(steps)]
    return out


def _at_start(ep: Episode) -> RobotStates:
    r = ep.robots[0]
    return _robots([(r.start.x, r.start.y)], [r.model.circumscribed_radius])


# -- registration, building, config ----------------------------------------------------------
def test_the_config_builds_the_models_own_driver_and_warns_once_about_what_it_ignores() -> None:
    warn_once.cache_clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        a = build_driver("fast_social_force", PedestrianConfig())
        b = build_driver({"type": "fast_social_force", "cutoff": 2.0}, PedestrianConfig())
    assert isinstance(a, FastSocialForceDriver) and isinstance(b, FastSocialForceDriver)
    assert b.params.cutoff == 2.0
    assert [str(w.message) for w in caught] == [  # once, though two drivers were built
        "crowd 'fast_social_force' has no social states and no groups: "
        "pedestrians.social_states and pedestrians.group_fraction ignored"
    ]
    warn_once.cache_clear()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing asked for that it ignores: no warning
        build_driver("fast_social_force", PedestrianConfig(social_states=False, group_fraction=0))
        build_driver("fast_social_force")
    assert isinstance(build_driver("waypoint_walker"), CrowdSimulator)  # the others: simulator


def test_config_validates_its_params_and_bad_ones_give_one_line() -> None:
    cfg = load_config(overrides=["crowd.type=fast_social_force", "crowd.wall_factor=5"])
    assert cfg.crowd == {"type": "fast_social_force", "wall_factor": 5}
    with pytest.raises(ConfigError) as bad_key:
        load_config(overrides=["crowd.type=fast_social_force", "crowd.ped_factr=1"])
    assert "crowd.ped_factr" in str(bad_key.value) and "\n" not in str(bad_key.value)
    with pytest.raises(ConfigError) as bad_value:
        load_config(overrides=["crowd.type=fast_social_force", "crowd.cutoff=-1"])
    assert "crowd.cutoff" in str(bad_value.value) and "greater than 0" in str(bad_value.value)
    assert FastSocialForceModel.Params is FastSocialForceParams


def test_a_bad_param_on_the_command_line_is_one_line(monkeypatch, capsys) -> None:
    code, out, err = run_cli(monkeypatch, capsys, "run", "crowd.type=fast_social_force",
                             "crowd.cutoff=0")
    assert code == 2 and "Traceback" not in out + err
    assert " ".join(err.split()) == (
        "error: override 'crowd.cutoff=0': crowd.cutoff: Input should be greater than 0 (got 0)"
    )


# -- reference values -------------------------------------------------------------------------
def test_obstacle_edge_forces_match_the_formula_near_and_far() -> None:
    # Four 1 m boxes in a 20 m room; one pedestrian per box: beside an edge (in reach), off a
    # corner (outside the box's extent on both axes, but in reach), beyond the cutoff, and below
    # an edge. The first step's velocity is the goal term plus every edge within the cutoff
    # (the kernel skips edge runs whose bounding box is out of reach; this catches one skipped
    # wrongly). Walls, the robot and the other pedestrians are out of reach.
    square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    centres = [(5.0, 5.0), (14.0, 5.0), (5.0, 14.0), (14.0, 14.0)]
    obstacles = tuple(
        Obstacle(f"box{k}", "cuboid", np.array([x, y, 0.0]), square)
        for k, (x, y) in enumerate(centres)
    )
    peds = np.array([[5.0, 6.2], [16.0, 7.0], [9.5, 14.0], [14.0, 12.8]])
    n = len(peds)
    wps = (peds + np.array([2.0, 0.0]))[:, None, :]
    driver = FastSocialForceDriver()
    driver.reset(_spawn(peds, wps), StaticWorld.build(_room(), obstacles),
                 np.random.default_rng(0))
    st = driver.step(_robots([(10.0, 2.5)], [0.3]), DT)

    p = FastSocialForceParams()
    tau, a_w, b_w = p.relaxation_time, p.wall_factor, p.wall_range
    cutoff, cap = p.cutoff, p.max_speed_factor * 1.2
    edges = [(o.polygon[k], o.polygon[(k + 1) % 4]) for o in obstacles for k in range(4)]
    expected = np.zeros((n, 2))
    pushed = np.zeros(n)
    for a, q0 in enumerate(peds):
        acc = 1.2 * np.array([1.0, 0.0]) / tau  # toward the waypoint 2 m ahead, from rest
        for q, b in edges:
            e = b - q
            t = np.clip(np.dot(q0 - q, e) / np.dot(e, e), 0.0, 1.0)
            off = q0 - q - t * e
            d = np.hypot(*off)
            if d < cutoff:
                acc = acc + a_w * np.exp((0.3 - d) / b_w) * off / d
                pushed[a] += 1
        v = acc * DT
        speed = np.hypot(*v)
        expected[a] = v * (cap / speed) if speed > cap else v
    assert pushed.tolist() == [4, 4, 0, 4]  # edges in reach of each pedestrian
    np.testing.assert_allclose(st.velocities, expected, rtol=1e-9, atol=1e-12)
    assert st.velocities[2, 1] == 0.0  # beyond the cutoff: no push at all
    np.testing.assert_allclose(st.positions, peds + expected * DT, rtol=0, atol=1e-12)


def test_every_robot_and_the_other_pedestrians_repel_as_the_formula_says() -> None:
    # Pedestrian 0 between two robots of different radii (both within the cutoff), 1 and 2 a
    # pair 1 m apart, 3 alone: the first step from rest is the goal term plus these repulsions.
    peds = np.array([[10.0, 10.0], [6.0, 6.0], [7.0, 6.0], [14.0, 6.0]])
    wps = (peds + np.array([0.0, 2.0]))[:, None, :]
    robots = _robots([(11.0, 10.5), (9.0, 9.0)], [0.45, 0.2])
    driver = FastSocialForceDriver(FastSocialForceParams(max_speed_factor=100.0))
    driver.reset(_spawn(peds, wps, vmax=1.0), StaticWorld.build(_room()),
                 np.random.default_rng(0))
    st = driver.step(robots, DT)
    p = driver.params
    acc = np.tile([0.0, 1.0 / p.relaxation_time], (4, 1))
    for xy, rad in zip(robots.poses[:, :2], robots.radii, strict=True):
        off = peds[0] - xy
        d = np.hypot(*off)
        acc[0] += p.robot_factor * np.exp((0.3 + rad - d) / p.robot_range) * off / d
    pair = p.ped_factor * np.exp((0.6 - 1.0) / p.ped_range)
    acc[1] += [-pair, 0.0]
    acc[2] += [pair, 0.0]
    np.testing.assert_allclose(st.velocities, acc * DT, rtol=1e-12, atol=1e-15)
    assert st.velocities[3, 0] == 0.0 and st.velocities[0, 0] < 0.0  # pushed off both robots


def test_pair_repulsion_through_cells_equals_all_pairs_and_is_antisymmetric() -> None:
    from arena.crowd.models.fast_social_force.kernels import pair_repulsion

    rng = np.random.default_rng(5)
    # 300 people over 40 x 25 m (many cells), two coincident, one pair at exactly the cutoff
    pos = rng.uniform([0.0, 0.0], [40.0, 25.0], (300, 2))
    pos[7] = pos[3]
    pos[11] = pos[10] + [3.0, 0.0]
    radii = rng.uniform(0.2, 0.35, 300)
    a_p, b_p, cutoff = 2.1, 0.3, 3.0
    got = pair_repulsion(pos, radii, a_p, b_p, cutoff)
    off = pos[:, None] - pos[None]
    d = np.hypot(off[..., 0], off[..., 1])
    np.fill_diagonal(d, np.inf)
    near = d < cutoff
    assert not near[10, 11]  # at the cutoff: no force
    d_eff = np.where(d < 1e-9, 1.0, d)
    unit = np.where((d < 1e-9)[..., None], 0.0, off / d_eff[..., None])
    unit[3, 7], unit[7, 3] = [-1.0, 0.0], [1.0, 0.0]  # coincident: lower index toward -x
    f = np.where(near, a_p * np.exp((radii[:, None] + radii[None] - d_eff) / b_p), 0.0)
    expected = (f[..., None] * unit).sum(axis=1)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    assert near.sum() > 300  # plenty of pairs, across cell borders
    assert np.abs(got.sum(axis=0)).max() < 1e-12  # each pair adds opposite forces
    assert pair_repulsion(pos[:1], radii[:1], a_p, b_p, cutoff).tolist() == [[0.0, 0.0]]


# -- behaviour --------------------------------------------------------------------------------
def test_people_walk_their_loops_in_order() -> None:
    corners = np.array([[4.0, 4.0], [16.0, 4.0], [16.0, 16.0], [4.0, 16.0]])
    pos = np.array([[4.0, 4.0], [16.0, 16.0]])
    wps = np.stack([corners, np.roll(corners, -2, axis=0)])  # both walk the same square
    driver = FastSocialForceDriver()
    driver.reset(_spawn(pos, wps), StaticWorld.build(_room()), np.random.default_rng(0))
    visits: list[list[int]] = [[0], [0]]
    far = _robots([(-50.0, -50.0)], [0.3])
    for _ in range(600):
        driver.step(far, DT)
        s = driver.state
        np.testing.assert_array_equal(s.destinations, s.current_waypoints)
        for a in range(2):
            k = int(s.waypoint_index[a])
            if k != visits[a][-1]:
                visits[a].append(k)
    # 60 s at up to 1.56 m/s around a 48 m square: at least one full loop each, in order
    for seq in visits:
        assert len(seq) >= 5
        assert seq == [k % 4 for k in range(len(seq))]


def test_random_waypoints_are_drawn_from_the_seed_and_never_repeat_the_current_one() -> None:
    # Eight people, five waypoints 2 m apart each: hundreds of arrivals, so the table of
    # uniforms is redrawn from the generator several times.
    rng = np.random.default_rng(11)
    wps = rng.uniform(7.0, 13.0, (8, 5, 2))
    pos = wps[:, 4].copy()
    spawn = _spawn(pos, wps, mode=WAYPOINT_RANDOM)
    far = _robots([(-50.0, -50.0)], [0.3])

    def sequences(seed: int) -> list[list[int]]:
        driver = FastSocialForceDriver(FastSocialForceParams(ped_factor=0.0))
        driver.reset(spawn, StaticWorld.build(_room()), np.random.default_rng(seed))
        seqs = [[0] for _ in range(8)]
        for _ in range(1500):
            driver.step(far, DT)
            for a, k in enumerate(driver.state.waypoint_index.tolist()):
                if k != seqs[a][-1]:
                    seqs[a].append(k)
        return seqs

    a, b, c = sequences(1), sequences(1), sequences(2)
    assert sum(len(s) - 1 for s in a) > 300  # arrivals: more than two tables of 128
    for seq in a:
        assert set(seq) == {0, 1, 2, 3, 4}  # every waypoint is chosen
        assert all(x != y for x, y in itertools.pairwise(seq))
    assert a == b  # same seed, same choices
    assert a != c  # the choices come from the generator


def test_pedestrians_avoid_walls_and_each_other(tmp_path) -> None:
    # BatchSim's crowd test, carried over: eight 10 x 10 m episodes with a wall across, three
    # boxes and six people; 200 steps with the robot standing at its start.
    from arena.maps.io import save_map

    occ = np.zeros((200, 200), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[100:104, 0:120] = True
    path = tmp_path / "m.yaml"
    save_map(OccupancyGrid.from_occupied(occ, 0.05), path)
    task = TaskConfig(
        robots={"type": "random", "min_goal_distance": 2.0, "clearance": 1.0},
        obstacles={"type": "random", "static": 3, "dynamic": 6},
    )
    gen = TaskGenerator(task, map_spec={"type": "file", "path": str(path)},
                        robots=[load_robot("jackal")], seed=3)
    min_gap, walked = np.inf, 0.0
    for ep in (gen.episode(i) for i in range(8)):
        states = _run(FastSocialForceDriver(), ep, _at_start(ep), 200, seed=1)
        n = len(ep.agents)
        for st in states[1:]:
            p = st.positions
            d = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))
            d[np.arange(n), np.arange(n)] = np.inf
            min_gap = min(min_gap, d.min())
        p = states[-1].positions
        walked = max(walked, np.abs(p - states[0].positions).max())
        g = ep.grid
        col = ((p[:, 0] - g.origin[0]) // g.resolution).astype(int)
        row = ((p[:, 1] - g.origin[1]) // g.resolution).astype(int)
        assert not g.occupied[row, col].any()
        assert (np.asarray(g.distance)[row, col] > 0).all()
    assert min_gap > 0.2  # nobody walks through anybody
    assert walked > 1.0  # they do walk


def test_people_keep_off_walls_and_obstacles_on_a_packaged_world(office_episode: Episode) -> None:
    ep = office_episode
    grid = ep.grid
    states = _run(FastSocialForceDriver(), ep, _at_start(ep), 1500)
    pos = np.array([s.positions for s in states])  # (steps + 1, n, 2)
    radii = states[0].radii
    assert np.hypot(*(pos[-1] - pos[0]).T).max() > 5.0  # they do walk
    # Distance from each centre to the nearest blocking cell (a square of the map), among
    # the 8 nearest cell centres: the body never reaches a wall (to within half a cell, the
    # kernel's distance transform being the cell's).
    rows, cols = np.nonzero(grid.occupied)
    res = grid.resolution
    cells = np.stack([grid.origin[0] + (cols + 0.5) * res, grid.origin[1] + (rows + 0.5) * res], 1)
    flat = pos.reshape(-1, 2)
    _, near = cKDTree(cells).query(flat, k=8)
    gap = np.hypot(*np.maximum(np.abs(cells[near] - flat[:, None]) - res / 2, 0.0).T).min(0)
    assert (gap - np.tile(radii, len(states))).min() > -res / 2
    # Obstacles repel (no hard constraint): nobody's body touches one in this episode.
    for ob in ep.obstacles:
        poly = ob.polygon
        assert not PolygonPath(poly).contains_points(flat).any()
        a, e = poly, np.roll(poly, -1, axis=0) - poly
        t = np.clip(((flat[:, None] - a) * e).sum(-1) / (e * e).sum(-1), 0.0, 1.0)
        d = np.hypot(*(flat[:, None] - a - t[..., None] * e).transpose(2, 0, 1)).min(1)
        assert (d - np.tile(radii, len(states))).min() > 0.0


def test_repulsion_keeps_people_apart_and_off_the_robot(office_episode: Episode) -> None:
    ep = office_episode
    robots = _at_start(ep)

    def closest(**params: float) -> tuple[float, float]:
        states = _run(FastSocialForceDriver(FastSocialForceParams(**params)), ep, robots, 1000)
        pair, robot = np.inf, np.inf
        for s in states[1:]:
            p = s.positions
            d = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))
            np.fill_diagonal(d, np.inf)
            pair = min(pair, d.min())
            robot = min(robot, np.hypot(*(p - robots.poses[0, :2]).T).min())
        return pair, robot

    pair, robot = closest()
    no_pair, _ = closest(ped_factor=0.0)
    _, no_robot = closest(robot_factor=0.0)
    assert pair > 0.3 and no_pair < 0.1  # centres: people pass each other, not through
    touch = 0.3 + robots.radii[0]  # a pedestrian's body and the robot's circle meet
    assert robot > touch and no_robot < 0.1


def test_same_seed_same_crowd_and_the_state_codes(office_episode: Episode) -> None:
    ep = office_episode
    a = _run(FastSocialForceDriver(), ep, _at_start(ep), 200, seed=4)
    b = _run(FastSocialForceDriver(), ep, _at_start(ep), 200, seed=4)
    for x, y in zip(a, b, strict=True):
        for name in ("positions", "velocities", "headings"):
            assert np.array_equal(getattr(x, name), getattr(y, name))
    last = a[-1]
    assert (last.states == SocialState.WALKING).all()  # no social states: everyone walks
    assert np.array_equal(last.ids, np.arange(len(ep.agents)))
    assert np.array_equal(last.kinds, ep.agents.kinds)
    moving = np.hypot(*last.velocities.T) > 0.05
    assert moving.any()
    np.testing.assert_allclose(  # heading follows the motion
        last.headings[moving], np.arctan2(last.velocities[moving, 1], last.velocities[moving, 0])
    )


def test_groups_and_start_up_modes_of_the_spawn_are_ignored() -> None:
    pos = np.array([[5.0, 5.0], [6.0, 5.0]])
    wps = np.array([[[5.0, 15.0]], [[6.0, 15.0]]])
    base = _spawn(pos, wps)
    spawn = AgentSpawn(
        positions=pos, radii=base.radii, vmax=base.vmax, waypoints=wps,
        num_waypoints=base.num_waypoints, waypoint_mode=base.waypoint_mode, kinds=base.kinds,
        groups=np.array([0, 0]), startup_mode=np.array([1, 2]), wait_time=np.array([50.0, 0.0]),
        trigger_radius=np.array([0.0, 0.1]),
    )
    far = _robots([(-50.0, -50.0)], [0.3])
    runs = []
    warn_once.cache_clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for sp in (base, spawn, spawn):
            driver = FastSocialForceDriver()
            driver.reset(sp, StaticWorld.build(_room()), np.random.default_rng(0))
            runs.append([driver.step(far, DT).positions for _ in range(20)])
    assert [str(w.message) for w in caught] == [  # once, for the spawn that has them
        "crowd 'fast_social_force' has no groups and no start-up modes: the episode's "
        "pedestrian groups and start-up modes ignored"
    ]
    assert np.array_equal(np.array(runs[0]), np.array(runs[1]))  # both walk at once, alone
    assert runs[1][-1][0, 1] > 6.0


def test_no_pedestrians() -> None:
    driver = FastSocialForceDriver()
    s0 = driver.reset(AgentSpawn.empty(), StaticWorld.build(_room()), np.random.default_rng(0))
    s1 = driver.step(_robots([(3.0, 3.0)], [0.3]), DT)
    assert len(s0) == len(s1) == 0 and driver.state.time == DT


# -- end to end -------------------------------------------------------------------------------
def test_arena_run_with_the_fast_crowd(monkeypatch, capsys, tmp_path) -> None:
    warn_once.cache_clear()
    out = tmp_path / "run"
    code, stdout, err = run_cli(
        monkeypatch, capsys, "run", "crowd.type=fast_social_force", "-n", "2",
        "task.obstacles.dynamic=5", "task.timeout=6", "--no-video", "--out", str(out),
    )
    assert code == 0, stdout + err
    assert err.count("has no social states and no groups") == 1  # one line, once per run
    summary = list(csv.DictReader((out / "summary.csv").open()))
    assert len(summary) == 2 and all(row["error"] == "" for row in summary)
    for ep in ("episode_000", "episode_001"):
        rows = list(csv.DictReader((out / ep / "agents.csv").open()))
        assert {r["state"] for r in rows} == {str(int(SocialState.WALKING))}
        first = {r["id"]: (float(r["x"]), float(r["y"])) for r in rows if r["step"] == "0"}
        last_step = max(int(r["step"]) for r in rows)
        last = {r["id"]: (float(r["x"]), float(r["y"])) for r in rows
                if int(r["step"]) == last_step}
        assert len(first) == 5
        assert max(np.hypot(*np.subtract(last[k], first[k])) for k in first) > 1.0


def test_a_robot_spawn_episode_runs_in_native2d() -> None:
    # The driver behind the reference backend: people see the robot where it stands.
    from arena.sim.native2d import Native2DBackend

    pos = np.array([[5.0, 10.2]])  # a little off the robot's centre line: it walks around
    wps = np.array([[[15.0, 10.2]]])
    robot = RobotSpawn("r", load_robot("burger"), Pose2D(8.0, 10.0, 0.0), Pose2D(8.0, 2.0, 0.0))
    ep = Episode(0, 0, "room", _room(), (), (robot,), _spawn(pos, wps), 30.0)
    backend = Native2DBackend()
    backend.reset(ep, build_driver("fast_social_force"), np.random.default_rng(0))
    gap = np.inf
    for _ in range(150):
        s = backend.step(np.zeros((1, 3)), DT)
        gap = min(gap, float(np.hypot(*(s.agents.positions[0] - [8.0, 10.0]))))
    assert s.agents.positions[0, 0] > 12.0  # got past the robot
    assert gap > 0.3 + load_robot("burger").circumscribed_radius  # without touching it


@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")  # Arena's raw units
@pytest.mark.filterwarnings("ignore:crowd 'fast_social_force' has no social states")
def test_social_nav_env_runs_on_the_fast_crowd(monkeypatch: pytest.MonkeyPatch) -> None:
    from gymnasium.utils.env_checker import check_env

    from arena.learn.env import SocialNavEnv
    from tests.learn.helpers import small_cfg, small_robot

    seen: list[AgentStates] = []  # what the model's driver returned, step by step
    step = FastSocialForceDriver.step

    def spied(self: FastSocialForceDriver, robots: RobotStates, dt: float) -> AgentStates:
        seen.append(step(self, robots, dt))
        return seen[-1]

    monkeypatch.setattr(FastSocialForceDriver, "step", spied)
    cfg = small_cfg("crowd.type=fast_social_force",
                    "learning.env.observation.pedestrians.enabled=true")
    env = SocialNavEnv(cfg, robot=small_robot())
    check_env(env, skip_render_check=True)
    env.reset(seed=3)
    seen.clear()
    for _ in range(20):
        env.step(0)
    assert len(seen) >= 20  # the env's people are this model's
    moved = seen[-1].positions - seen[0].positions
    assert len(seen[0]) == 3 and np.hypot(*moved.T).max() > 0.5


@pytest.mark.filterwarnings("ignore:crowd 'fast_social_force' has no social states")
def test_the_benchmark_runner_runs_the_fast_crowd(tmp_path) -> None:
    # What `arena bench` runs, in a worker process, with the crowd named by the base config.
    from arena.config.schema import ExperimentConfig
    from arena.eval.io import load_record
    from arena.eval.runner import run_benchmark
    from arena.eval.store import load_results
    from tests.eval._suites import stage

    suite = tmp_path / "suite.yaml"
    suite.write_text("stages:\n" + stage("people", 2, "burger", dynamic=(3, 3)))
    contest = tmp_path / "contest.yaml"
    contest.write_text("contestants:\n  - {name: pure_pursuit, local_planner: pure_pursuit}\n")
    cfg = ExperimentConfig(seed=0, crowd={"type": "fast_social_force"})
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=cfg)
    table = load_results(run)
    assert table.num_rows == 2 and set(table["error"].to_pylist()) <= {None, ""}
    for rel in table["record"].to_pylist():
        record = load_record(run / rel)
        assert record.meta.config["crowd"] == {"type": "fast_social_force"}  # as it ran
        assert set(record.ped_state.tolist()) == {int(SocialState.WALKING)}

"""BatchSim: equivalence with native2d, independence of worlds, determinism, contacts, crowd."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.sim.batch import KIND_WALL, BatchSim
from arena.sim.native2d import Native2DBackend
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator


@pytest.fixture(scope="module")
def episodes(tmp_path_factory: pytest.TempPathFactory) -> list[Episode]:
    """Eight 10 x 10 m episodes with a wall, obstacles and 6 pedestrians."""
    from arena.maps.io import save_map

    res = 0.05
    occ = np.zeros((200, 200), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[100:104, 0:120] = True
    path = tmp_path_factory.mktemp("maps") / "m.yaml"
    save_map(OccupancyGrid.from_occupied(occ, res), path)
    task = TaskConfig(
        robots={"type": "random", "min_goal_distance": 2.0, "clearance": 1.0},
        obstacles={"type": "random", "static": 3, "dynamic": 6},
    )
    gen = TaskGenerator(
        task, map_spec={"type": "file", "path": str(path)}, robots=[load_robot("jackal")], seed=3
    )
    return [gen.episode(i) for i in range(8)]


def _commands(steps: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(7)
    c = np.zeros((steps, n, 3))
    c[:, :, 0] = rng.uniform(-0.3, 0.8, (steps, n))
    c[:, :, 2] = rng.uniform(-1.0, 1.0, (steps, n))
    return c


def test_batch_matches_native2d_with_standing_pedestrians(episodes: list[Episode]) -> None:
    sim = BatchSim(1, BatchSim.Params(pedestrians="static"))
    ref = Native2DBackend()
    ep = episodes[0]
    s = sim.reset([ep], np.random.default_rng(0))
    r = ref.reset(ep, None, np.random.default_rng(0))
    np.testing.assert_allclose(s.scans[0], r.robots.scans[0], atol=1e-6)
    for cmd in _commands(40, 1):
        s = sim.step(cmd, 0.05)
        r = ref.step(cmd, 0.05)
        if r.collisions.any[0] or s.collided[0]:
            break  # contact footprints differ (circle vs polygon) by design
        np.testing.assert_array_equal(s.poses, r.robots.poses)
        np.testing.assert_array_equal(s.twists, r.robots.twists)
        np.testing.assert_allclose(s.scans[0], r.robots.scans[0], atol=1e-6)
    assert s.step[0] > 10


def test_world_zero_does_not_depend_on_other_worlds(episodes: list[Episode]) -> None:
    one = BatchSim(1)
    eight = BatchSim(8)
    a = one.reset(episodes[:1], np.random.default_rng(5))
    b = eight.reset(episodes, np.random.default_rng(5))
    cmds = _commands(30, 8)
    for c in cmds:
        a = one.step(c[:1], 0.1)
        b = eight.step(c, 0.1)
    np.testing.assert_array_equal(a.poses[0], b.poses[0])
    np.testing.assert_array_equal(a.scans[0], b.scans[0])
    p = a.ped_positions.shape[1]
    np.testing.assert_array_equal(a.ped_positions[0], b.ped_positions[0, :p])


def test_same_seed_same_rollout(episodes: list[Episode]) -> None:
    runs = []
    for _ in range(2):
        sim = BatchSim(4)
        sim.reset(episodes[:4], np.random.default_rng(11))
        for c in _commands(25, 4):
            st = sim.step(c, 0.1)
        runs.append(st)
    for name in ("poses", "twists", "scans", "ped_positions", "ped_velocities", "collided"):
        np.testing.assert_array_equal(getattr(runs[0], name), getattr(runs[1], name))


def test_collision_stops_robot(episodes: list[Episode]) -> None:
    sim = BatchSim(1, BatchSim.Params(pedestrians="static"))
    sim.reset(episodes[:1], np.random.default_rng(0))
    hit = None
    for _ in range(400):  # full speed ahead until something is hit
        st = sim.step(np.array([[1.0, 0.0, 0.0]]), 0.1)
        if st.collided[0]:
            hit = st
            break
    assert hit is not None
    np.testing.assert_array_equal(hit.twists[0], 0.0)
    assert hit.collision_kind[0] > 0
    again = sim.step(np.array([[1.0, 0.0, 0.0]]), 0.1)
    np.testing.assert_array_equal(again.poses[0], hit.poses[0])  # stays blocked


def test_wall_contact_kind() -> None:
    grid = OccupancyGrid.from_occupied(np.pad(np.zeros((96, 96), bool), 2, constant_values=True),
                                       0.05)
    from arena.core.types import Pose2D
    from arena.scene.episode import AgentSpawn, RobotSpawn

    jackal = load_robot("jackal")
    ep = Episode(0, 0, "box", grid, (), (RobotSpawn("r", jackal, Pose2D(2.5, 2.5, 0.0),
                                                    Pose2D(4.0, 2.5, 0.0)),),
                 AgentSpawn.empty(), 10.0)
    sim = BatchSim(2)
    sim.reset([ep, ep], np.random.default_rng(0))
    cmd = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    for _ in range(40):
        st = sim.step(cmd, 0.1)
    assert st.collision_kind[0] == KIND_WALL
    assert not st.collided[1]
    assert st.poses[0, 0] + jackal.circumscribed_radius <= 4.9 + 1e-9


def test_pedestrians_avoid_walls_and_each_other(episodes: list[Episode]) -> None:
    sim = BatchSim(8)
    st = sim.reset(episodes, np.random.default_rng(1))
    start = st.ped_positions.copy()
    min_gap = np.inf
    for _ in range(200):
        st = sim.step(np.zeros((8, 3)), 0.1)
        for w, ep in enumerate(episodes):
            n = len(ep.agents)
            p = st.ped_positions[w, :n]
            d = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))
            d[np.arange(n), np.arange(n)] = np.inf
            min_gap = min(min_gap, d.min())
    assert min_gap > 0.2  # nobody walks through anybody
    assert np.abs(st.ped_positions - start)[st.ped_mask].max() > 1.0  # they do walk
    for w, ep in enumerate(episodes):
        g = ep.grid
        p = st.ped_positions[w, : len(ep.agents)]
        col = ((p[:, 0] - g.origin[0]) // g.resolution).astype(int)
        row = ((p[:, 1] - g.origin[1]) // g.resolution).astype(int)
        assert not g.occupied[row, col].any()
        assert (np.asarray(g.distance)[row, col] > 0).all()


def test_reset_world_touches_only_that_world(episodes: list[Episode]) -> None:
    sim = BatchSim(3)
    sim.reset(episodes[:3], np.random.default_rng(2))
    for c in _commands(10, 3):
        before = sim.step(c, 0.1)
    after = sim.reset_world(1, episodes[5], np.random.default_rng(9))
    for name in ("poses", "twists", "scans", "ped_positions", "time", "step"):
        a, b = getattr(before, name), getattr(after, name)
        np.testing.assert_array_equal(a[[0, 2]], b[[0, 2]])
    assert after.step[1] == 0 and after.time[1] == 0.0
    np.testing.assert_array_equal(after.poses[1], episodes[5].robots[0].start.as_array())
    fresh = BatchSim(1)
    ref = fresh.reset([episodes[5]], np.random.default_rng(9).spawn(1)[0])
    # world 1 sees what a fresh world in that episode sees
    np.testing.assert_array_equal(after.scans[1], ref.scans[0])


def test_worlds_with_other_kinematics_regroup_on_model_change(episodes: list[Episode]) -> None:
    # World 1 gets an omnidirectional copy of the jackal (same lidar): a lateral command moves
    # it sideways but not the diff-drive worlds; a reset with the jackal again undoes that.
    from dataclasses import replace

    jackal = episodes[0].robots[0].model
    omni = load_robot("ridgeback").model_copy(update={"laser": jackal.laser})
    assert omni.holonomic and not jackal.holonomic

    def with_model(ep: Episode, model: object) -> Episode:
        robot = replace(ep.robots[0], model=model)
        return replace(ep, robots=(robot,))

    sim = BatchSim(3, BatchSim.Params(pedestrians="static", collision_response="record"))
    start = sim.reset([episodes[0], with_model(episodes[1], omni), episodes[2]],
                      np.random.default_rng(0))
    assert len(sim._groups) == 2
    lateral = np.tile([0.0, 0.5, 0.0], (3, 1))
    moved = sim.step(lateral, 0.1)
    body = moved.poses[:, :2] - start.poses[:, :2]
    heading = start.poses[:, 2]
    sideways = -np.sin(heading) * body[:, 0] + np.cos(heading) * body[:, 1]
    assert sideways[1] > 0.01
    np.testing.assert_allclose(sideways[[0, 2]], 0.0, atol=1e-12)
    # the same model again: nothing rebuilt; the jackal back in world 1: one group again
    kin = sim._kin[0]
    sim.reset_world(0, episodes[3], np.random.default_rng(1))
    assert sim._kin[0] is kin and len(sim._groups) == 2
    back = sim.reset_world(1, episodes[1], np.random.default_rng(2))
    assert len(sim._groups) == 1
    again = sim.step(lateral, 0.1)
    assert np.all(np.hypot(*(again.poses[:, :2] - back.poses[:, :2]).T) < 1e-12)


def test_reset_world_with_another_map_keeps_shared_map(episodes: list[Episode]) -> None:
    from arena.core.types import Pose2D
    from arena.scene.episode import AgentSpawn, RobotSpawn

    grid = OccupancyGrid.from_occupied(np.pad(np.zeros((76, 96), bool), 2, constant_values=True),
                                       0.05)
    spawn = RobotSpawn("r", load_robot("jackal"), Pose2D(2.0, 2.0, 0.3), Pose2D(4.0, 2.0, 0.0))
    box = Episode(0, 0, "box", grid, (), (spawn,), AgentSpawn.empty(), 10.0)
    sim = BatchSim(3, BatchSim.Params(pedestrians="static"))
    before = sim.reset(episodes[:3], np.random.default_rng(0))  # all three share one grid
    after = sim.reset_world(1, box, np.random.default_rng(1))
    np.testing.assert_array_equal(after.scans[[0, 2]], before.scans[[0, 2]])
    fresh = BatchSim(1).reset([box], np.random.default_rng(1))
    np.testing.assert_array_equal(after.scans[1], fresh.scans[0])
    back = sim.reset_world(1, episodes[1], np.random.default_rng(2))
    np.testing.assert_array_equal(back.scans, before.scans)


@pytest.mark.parametrize("parallel_min_worlds", [1, 100])  # thread pool and serial path
@pytest.mark.parametrize("faces_per_beam", [math.inf, -1.0])  # walls as faces / grid walk
def test_scans_bit_identical_to_lidar2d(
    episodes: list[Episode], parallel_min_worlds: int, faces_per_beam: float, monkeypatch
) -> None:
    import arena.sensors.lidar2d.model as mod
    from arena.sensors.lidar2d import Lidar2D

    monkeypatch.setattr(mod, "FACES_PER_BEAM", faces_per_beam)

    sim = BatchSim(8, BatchSim.Params(parallel_min_worlds=parallel_min_worlds))
    s = sim.reset(episodes, np.random.default_rng(2))
    for c in _commands(12, 8):
        s = sim.step(c, 0.1)
    lidar = Lidar2D(sim.lidar_spec)
    for i, ep in enumerate(episodes):
        a = np.concatenate([ob.polygon for ob in ep.obstacles]) if ep.obstacles else None
        b = (
            np.concatenate([np.roll(ob.polygon, -1, axis=0) for ob in ep.obstacles])
            if ep.obstacles else None
        )
        lidar.bind(ep.grid, a, b)
        m = s.ped_mask[i]
        ref = lidar.scan(s.poses[i], s.ped_positions[i][m], s.ped_radii[i][m])
        np.testing.assert_array_equal(s.scans[i], ref)


def test_worlds_mix_wall_faces_and_grid_walk() -> None:
    """A speckled map (thousands of faces: grid walk) next to rooms cast as faces, with the
    padded face table growing when a later world's map has more faces."""
    from arena.core.types import Pose2D
    from arena.scene.episode import AgentSpawn, RobotSpawn
    from arena.sensors.lidar2d import Lidar2D, use_wall_faces, wall_faces

    jackal = load_robot("jackal")
    rng = np.random.default_rng(4)
    room = np.pad(np.zeros((96, 96), bool), 2, constant_values=True)
    pillars = room.copy()
    pillars[20:80:10, 20:80:10] = True  # 36 more boxes: more faces than the plain room
    speckle = room | (rng.random(room.shape) < 0.06)
    speckle[40:60, 40:60] = False  # room for the robot
    grids = [OccupancyGrid.from_occupied(m, 0.05) for m in (room, speckle, pillars)]
    assert [use_wall_faces(wall_faces(g), jackal.laser.num_beams) for g in grids] == [
        True, False, True]
    assert len(wall_faces(grids[2])) > len(wall_faces(grids[0]))

    def episode(g: OccupancyGrid) -> Episode:
        return Episode(0, 0, "box", g, (), (RobotSpawn("r", jackal, Pose2D(2.5, 2.5, 0.3),
                                                       Pose2D(4.0, 2.5, 0.0)),),
                       AgentSpawn.empty(), 10.0)

    sim = BatchSim(3)
    s = sim.reset([episode(grids[0]), episode(grids[1]), episode(grids[0])],
                  np.random.default_rng(0))
    s = sim.reset_world(2, episode(grids[2]), np.random.default_rng(1))  # grows the table
    lidar = Lidar2D(jackal.laser)
    for _ in range(3):
        s = sim.step(np.tile([[0.3, 0.0, 0.5]], (3, 1)), 0.1)
        for i, g in enumerate(grids):
            lidar.bind(g)
            np.testing.assert_array_equal(s.scans[i], lidar.scan(s.poses[i]))


def test_obstacle_edge_forces_match_the_formula_near_and_far() -> None:
    # Four 1 m boxes in a 20 m room; one pedestrian per box: beside an edge (in reach), off a
    # corner (outside the box's extent on both axes, but in reach), beyond the cutoff, and below
    # an edge. The first step's velocity is the goal term plus every edge within the cutoff
    # (the kernel skips edge runs whose bounding box is out of reach; this catches one skipped
    # wrongly). Walls, the robot and the other pedestrians are out of reach.
    from arena.core.types import Pose2D
    from arena.scene.episode import WAYPOINT_LOOP, AgentSpawn, RobotSpawn
    from arena.scene.state import Obstacle
    from arena.sim.batch import kernels as K

    grid = OccupancyGrid.from_occupied(np.pad(np.zeros((396, 396), bool), 2, constant_values=True),
                                       0.05)
    square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    centres = [(5.0, 5.0), (14.0, 5.0), (5.0, 14.0), (14.0, 14.0)]
    obstacles = tuple(
        Obstacle(f"box{k}", "cuboid", np.array([x, y, 0.0]), square)
        for k, (x, y) in enumerate(centres)
    )
    peds = np.array([[5.0, 6.2], [16.0, 7.0], [9.5, 14.0], [14.0, 12.8]])
    n = len(peds)
    wps = np.full((n, 1, 2), np.nan)
    wps[:, 0] = peds + np.array([2.0, 0.0])
    agents = AgentSpawn(
        positions=peds, radii=np.full(n, 0.3), vmax=np.full(n, 1.2), waypoints=wps,
        num_waypoints=np.ones(n, np.int64), waypoint_mode=np.full(n, WAYPOINT_LOOP),
        kinds=np.zeros(n, np.int64),
    )
    robot = RobotSpawn("r", load_robot("jackal"), Pose2D(10.0, 2.5, 0.0), Pose2D(12.0, 2.5, 0.0))
    ep = Episode(0, 0, "room", grid, obstacles, (robot,), agents, 10.0)
    sim = BatchSim(1)
    sim.reset([ep], np.random.default_rng(0))
    dt = 0.1
    st = sim.step(np.zeros((1, 3)), dt)

    prm = sim._crowd_prm
    tau, a_w, b_w = prm[K.P_TAU], prm[K.P_A_WALL], prm[K.P_B_WALL]
    cutoff, cap = prm[K.P_CUTOFF], prm[K.P_VFAC] * 1.2
    edges = [(o.polygon[k], o.polygon[(k + 1) % 4]) for o in obstacles for k in range(4)]
    expected = np.zeros((n, 2))
    pushed = np.zeros(n)
    for a, p in enumerate(peds):
        acc = 1.2 * np.array([1.0, 0.0]) / tau  # toward the waypoint 2 m ahead, from rest
        for q, b in edges:
            e = b - q
            t = np.clip(np.dot(p - q, e) / np.dot(e, e), 0.0, 1.0)
            off = p - q - t * e
            d = np.hypot(*off)
            if d < cutoff:
                acc = acc + a_w * np.exp((0.3 - d) / b_w) * off / d
                pushed[a] += 1
        v = acc * dt
        speed = np.hypot(*v)
        expected[a] = v * (cap / speed) if speed > cap else v
    assert pushed.tolist() == [4, 4, 0, 4]  # edges in reach of each pedestrian
    np.testing.assert_allclose(st.ped_velocities[0, :n], expected, rtol=1e-9, atol=1e-12)
    assert st.ped_velocities[0, 2, 1] == 0.0  # beyond the cutoff: no push at all


def test_pedestrian_mask_follows_reloaded_worlds(episodes: list[Episode]) -> None:
    from dataclasses import replace

    from arena.scene.episode import AgentSpawn

    sim = BatchSim(2)
    st = sim.reset(episodes[:2], np.random.default_rng(0))
    n = len(episodes[0].agents)
    assert st.ped_mask[:, :n].all() and not st.ped_mask[:, n:].any()
    assert (st.ped_states[st.ped_mask] == 0).all() and (st.ped_states[~st.ped_mask] == -1).all()
    with pytest.raises(ValueError):
        st.ped_mask[0, 0] = False  # shared by snapshots: read-only
    empty = replace(episodes[2], agents=AgentSpawn.empty())
    after = sim.reset_world(1, empty, np.random.default_rng(1))
    assert after.ped_mask[0, :n].all() and not after.ped_mask[1].any()
    assert (after.ped_states[1] == -1).all()
    assert st.ped_mask[1, :n].all()  # the earlier snapshot is unchanged
    stepped = sim.step(np.zeros((2, 3)), 0.1)
    np.testing.assert_array_equal(stepped.ped_mask, after.ped_mask)

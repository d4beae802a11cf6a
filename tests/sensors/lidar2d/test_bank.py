"""Tests of :class:`arena.sensors.lidar2d.LidarBank`: every lidar of every world, one kernel.

The reference is :meth:`Lidar2D.scan_many` of the same world (and, for the owner rule, native2d's
way of leaving a robot's own body out of the geometry it passes to :meth:`Lidar2D.scan`): each
bank row must give bit-identical ranges, serially and on the thread pool, whatever the other
worlds, their number and the row's position.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.core.geometry import rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D, LidarSpec
from arena.sensors.lidar2d import LidarBank, use_wall_faces, wall_faces

FRONT = LidarSpec(
    angle_min=-2.356, angle_max=2.356, num_beams=270, range_max=12.0, range_min=0.05,
    mount=(0.15, 0.0, 0.0),
)
REAR = LidarSpec(
    angle_min=-1.2, angle_max=1.2, num_beams=97, range_max=6.0, range_min=0.02,
    mount=(-0.2, 0.05, math.pi),
)
ROUND = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=360, range_max=9.0)
SPECS = (FRONT, REAR, ROUND)


@dataclass(frozen=True, eq=False)
class Scene:
    """The dynamic geometry of several worlds in the engine's flat layout."""

    circ_off: np.ndarray
    circ_xy: np.ndarray
    circ_r: np.ndarray
    circ_owner: np.ndarray
    seg_off: np.ndarray
    seg_a: np.ndarray
    seg_b: np.ndarray
    seg_owner: np.ndarray


@dataclass
class World:
    """One world: static geometry, pedestrians and robots (``None`` radius: a box robot)."""

    grid: OccupancyGrid
    obst_a: np.ndarray
    obst_b: np.ndarray
    peds: np.ndarray  # (p, 2)
    ped_r: np.ndarray  # (p,)
    poses: np.ndarray  # (n, 3)
    radius: list[float | None]
    sensors: list[list[LidarSpec]]  # per robot


def walled_grid(noisy: bool, seed: int) -> OccupancyGrid:
    """12 × 12 m at 0.1 m: a border and a wall (few faces), or salt noise (many faces)."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((120, 120), dtype=bool)
    occ[:2] = occ[-2:] = occ[:, :2] = occ[:, -2:] = True
    occ[60:63, 15:70] = True
    if noisy:
        occ |= rng.random(occ.shape) < 0.03
    return OccupancyGrid.from_occupied(occ, 0.1, origin=(-1.0, 0.5))


def random_world(rng: np.random.Generator, grid: OccupancyGrid) -> World:
    """Obstacles, pedestrians and 1–3 robots (round and box) with one or two sensors each."""
    x0, y0 = grid.origin
    k = int(rng.integers(0, 4))
    boxes = [
        transform_points(rectangle(*rng.uniform(0.3, 1.0, 2)),
                         [x0 + rng.uniform(1, 11), y0 + rng.uniform(1, 11), rng.uniform(-3, 3)])
        for _ in range(k)
    ]
    a = np.concatenate(boxes) if boxes else np.zeros((0, 2))
    b = np.concatenate([np.roll(p, -1, axis=0) for p in boxes]) if boxes else np.zeros((0, 2))
    p = int(rng.integers(0, 8))
    n = int(rng.integers(1, 4))
    return World(
        grid=grid, obst_a=a, obst_b=b,
        peds=np.column_stack([x0 + rng.uniform(0.5, 11.5, p), y0 + rng.uniform(0.5, 11.5, p)]),
        ped_r=rng.uniform(0.15, 0.35, p),
        poses=np.column_stack(
            [x0 + rng.uniform(0.5, 11.5, n), y0 + rng.uniform(0.5, 11.5, n),
             rng.uniform(-4, 4, n)]
        ),
        radius=[float(rng.uniform(0.2, 0.4)) if rng.random() < 0.5 else None for _ in range(n)],
        sensors=[[SPECS[i] for i in rng.permutation(3)[: int(rng.integers(1, 3))]]
                 for _ in range(n)],
    )


def body(world: World, j: int) -> tuple[np.ndarray | None, float | None]:
    """Robot ``j``'s box polygon ``(4, 2)`` (m, world frame) or its circle radius."""
    if world.radius[j] is not None:
        return None, world.radius[j]
    return transform_points(rectangle(0.6, 0.4), world.poses[j]), None


def pack(worlds: list[World]) -> tuple[np.ndarray, Scene, np.ndarray, np.ndarray, list]:
    """Global poses, the scene, and the sensor rows (world, robot row, spec) of ``worlds``."""
    poses, cxy, cr, co, sa, sb, so = [], [], [], [], [], [], []
    circ_off, seg_off = [0], [0]
    row_world, row_robot, specs = [], [], []
    base = 0
    for w, world in enumerate(worlds):
        cxy.append(world.peds)
        cr.append(world.ped_r)
        co.append(np.full(len(world.peds), -1))
        for j in range(len(world.poses)):
            poly, rad = body(world, j)
            if poly is None:
                cxy.append(world.poses[j : j + 1, :2])
                cr.append(np.array([rad]))
                co.append(np.array([base + j]))
            else:
                sa.append(poly)
                sb.append(np.roll(poly, -1, axis=0))
                so.append(np.full(4, base + j))
            for spec in world.sensors[j]:
                row_world.append(w)
                row_robot.append(base + j)
                specs.append(spec)
        poses.append(world.poses)
        base += len(world.poses)
        circ_off.append(sum(len(c) for c in cxy))
        seg_off.append(sum(len(s) for s in sa))
    scene = Scene(
        np.array(circ_off), np.concatenate(cxy).reshape(-1, 2), np.concatenate(cr),
        np.concatenate(co).astype(np.int64), np.array(seg_off),
        np.concatenate(sa) if sa else np.zeros((0, 2)),
        np.concatenate(sb) if sb else np.zeros((0, 2)),
        np.concatenate(so).astype(np.int64) if so else np.zeros(0, dtype=np.int64),
    )
    return np.concatenate(poses), scene, np.array(row_world), np.array(row_robot), specs


def reference(world: World) -> list[np.ndarray]:
    """Each sensor's ranges by :meth:`Lidar2D.scan_many` over the world's robots, in row order.

    Owners are the robots' local indices, as scan_many takes them.
    """
    cxy, cr, co = [world.peds], [world.ped_r], [np.full(len(world.peds), -1)]
    sa, sb, so = [], [], []
    for j in range(len(world.poses)):
        poly, rad = body(world, j)
        if poly is None:
            cxy.append(world.poses[j : j + 1, :2])
            cr.append(np.array([rad]))
            co.append(np.array([j]))
        else:
            sa.append(poly)
            sb.append(np.roll(poly, -1, axis=0))
            so.append(np.full(4, j))
    out = []
    for j, specs in enumerate(world.sensors):
        for spec in specs:
            lidar = Lidar2D(spec)
            lidar.bind(world.grid, world.obst_a, world.obst_b)
            out.append(lidar.scan_many(
                world.poses, np.concatenate(cxy).reshape(-1, 2), np.concatenate(cr),
                np.concatenate(sa) if sa else None, np.concatenate(sb) if sb else None,
                circles_owner=np.concatenate(co), segments_owner=np.concatenate(so) if so else None,
            )[j])
    return out


def build(worlds: list[World]) -> tuple[LidarBank, np.ndarray, Scene]:
    bank = LidarBank()
    for w, world in enumerate(worlds):
        bank.bind_world(w, world.grid, world.obst_a, world.obst_b)
    poses, scene, row_world, row_robot, specs = pack(worlds)
    bank.set_sensors(row_world, row_robot, specs)
    return bank, poses, scene


def rows_of(bank: LidarBank) -> list[np.ndarray]:
    return [bank.ranges(s).copy() for s in range(bank.num_rows)]


@pytest.fixture(scope="module")
def grids() -> tuple[OccupancyGrid, OccupancyGrid, OccupancyGrid]:
    """A map cast by faces, one cast by the grid walk, and an open map without walls."""
    faces, walk = walled_grid(False, 1), walled_grid(True, 2)
    for g, want in ((faces, True), (walk, False)):
        assert all(use_wall_faces(wall_faces(g), s.num_beams) is want for s in SPECS)
    return faces, walk, OccupancyGrid.empty(12.0, 12.0, 0.1, walls=False)


def worlds_for(seed: int, grids) -> list[World]:
    """Five worlds; worlds 0 and 3 share one grid object (one map slot)."""
    rng = np.random.default_rng(seed)
    order = (0, 1, 2, 0, 1)
    return [random_world(rng, grids[i]) for i in order]


@pytest.fixture
def two_threads():
    """numba's pool at (up to) 2 threads for the test; the assertions hold for any count."""
    previous = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    yield
    numba.set_num_threads(previous)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("parallel", [False, True])
def test_rows_equal_lidar2d_scan_many(seed: int, parallel: bool, grids, two_threads) -> None:
    worlds = worlds_for(seed, grids)
    # the scenes hold two-sensor robots, round and box robots, pedestrians and obstacles
    assert any(len(s) == 2 for world in worlds for s in world.sensors)
    radii = [r for world in worlds for r in world.radius]
    assert None in radii and any(r is not None for r in radii)
    assert sum(len(w.peds) for w in worlds) > 0 and sum(len(w.obst_a) for w in worlds) > 0
    bank, poses, scene = build(worlds)
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene, parallel=parallel)
    want = [r for world in worlds for r in reference(world)]
    got = rows_of(bank)
    assert len(got) == len(want) == bank.num_rows
    for s, (g, r) in enumerate(zip(got, want, strict=True)):
        assert np.array_equal(g, r), f"row {s}"
        assert g.shape == (bank.spec(s).num_beams,)
    assert any(np.any(g < bank.spec(s).range_max) for s, g in enumerate(got))


def test_owner_rule_is_leaving_the_own_body_out(grids) -> None:
    # native2d passes each robot the pedestrians plus the *other* robots' bodies, no owners.
    world = random_world(np.random.default_rng(5), grids[0])
    world.poses = np.array([[2.0, 3.0, 0.3], [3.5, 3.2, 2.0], [2.5, 4.5, -1.0]])
    world.radius = [0.3, None, None]
    world.sensors = [[FRONT], [REAR, ROUND], [ROUND]]
    bank, poses, scene = build([world])
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene)
    s = 0
    for j, specs in enumerate(world.sensors):
        cxy, cr, sa, sb = [world.peds], [world.ped_r], [], []
        for i in range(3):
            poly, rad = body(world, i)
            if i == j:
                continue
            if poly is None:
                cxy.append(world.poses[i : i + 1, :2])
                cr.append(np.array([rad]))
            else:
                sa.append(poly)
                sb.append(np.roll(poly, -1, axis=0))
        for spec in specs:
            lidar = Lidar2D(spec)
            lidar.bind(world.grid, world.obst_a, world.obst_b)
            want = lidar.scan(world.poses[j], np.concatenate(cxy), np.concatenate(cr),
                              np.concatenate(sa), np.concatenate(sb))
            assert np.array_equal(bank.ranges(s), want), f"robot {j} {spec.num_beams} beams"
            s += 1
    # the other robots are seen: robot 0's front lidar is shortened by the boxes ahead of it
    assert bank.ranges(0).min() < 2.0


def test_serial_equals_parallel_and_chunking(grids, two_threads) -> None:
    worlds = worlds_for(11, grids) * 3  # 15 worlds
    bank, poses, scene = build(worlds)
    due = np.ones(bank.num_rows, dtype=bool)
    bank.scan(due, poses, scene)
    serial = rows_of(bank)
    for chunk in (0, 1, 3):
        bank.scan(due, poses, scene, parallel=True, chunksize=chunk)
        assert all(np.array_equal(a, b) for a, b in zip(serial, rows_of(bank), strict=True))
    assert numba.get_parallel_chunksize() == 0  # restored


def test_world_rows_independent_of_w_and_other_worlds(grids) -> None:
    worlds = worlds_for(21, grids)
    bank, poses, scene = build(worlds)
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene, parallel=True)
    full = rows_of(bank)
    mine = np.flatnonzero(pack(worlds)[2] == 3)
    alone_bank, alone_poses, alone_scene = build([worlds[3]])
    alone_bank.scan(np.ones(alone_bank.num_rows, dtype=bool), alone_poses, alone_scene)
    assert len(mine) == alone_bank.num_rows
    for k, s in enumerate(mine):
        assert np.array_equal(full[s], alone_bank.ranges(k))
    # the same world at index 6 among other worlds (another W, other neighbours)
    others = worlds_for(99, grids)
    moved = [*others, others[1], worlds[3]]
    bank2, poses2, scene2 = build(moved)
    bank2.scan(np.ones(bank2.num_rows, dtype=bool), poses2, scene2, parallel=True)
    rows6 = np.flatnonzero(pack(moved)[2] == 6)
    for k, s in enumerate(rows6):
        assert np.array_equal(bank2.ranges(s), alone_bank.ranges(k))


def test_due_leaves_other_rows_untouched(grids) -> None:
    worlds = worlds_for(31, grids)
    bank, poses, scene = build(worlds)
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene)
    before = rows_of(bank)
    for world in worlds:
        world.poses[:, 2] += 0.7
        world.peds += 0.2
    poses, scene, *_ = pack(worlds)
    due = np.zeros(bank.num_rows, dtype=bool)
    due[::2] = True
    bank.scan(due, poses, scene, parallel=True)
    want = [r for world in worlds for r in reference(world)]
    for s in range(bank.num_rows):
        expected = want[s] if due[s] else before[s]
        assert np.array_equal(bank.ranges(s), expected), f"row {s}"
    assert not all(np.array_equal(a, b) for a, b in zip(before, want, strict=True))


def test_rebinding_worlds_with_other_grids(grids) -> None:
    rng = np.random.default_rng(41)
    worlds = worlds_for(41, grids)
    bank, poses, scene = build(worlds)
    # Many fresh grids through world 1 and world 4 (their slots are dropped and the buffers
    # compacted on the way), while world 0 and 3 keep the shared one.
    for k in range(12):
        for w in (1, 4):
            grid = walled_grid(k % 3 == 0, 100 + k) if k % 2 else OccupancyGrid.empty(
                float(rng.uniform(8, 14)), 12.0, 0.1
            )
            worlds[w] = random_world(rng, grid)
            bank.bind_world(w, grid, worlds[w].obst_a, worlds[w].obst_b)
        # world 4's robots draw their lidar afresh each episode (sensor randomisation)
        worlds[4].sensors = [
            [ROUND.model_copy(update={"num_beams": int(rng.integers(20, 400)),
                                      "range_max": float(rng.uniform(2.0, 9.0))})]
            for _ in worlds[4].sensors
        ]
        poses, scene, row_world, row_robot, specs = pack(worlds)
        bank.set_sensors(row_world, row_robot, specs)
        bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene)
        want = [r for world in worlds for r in reference(world)]
        assert all(np.array_equal(a, b) for a, b in zip(rows_of(bank), want, strict=True)), k
        assert len(bank._specs) <= len(set(specs))  # tables of specs no row uses are dropped
    # back to a grid shown before, and the same grid object in another world
    worlds[1] = random_world(rng, grids[0])
    bank.bind_world(1, grids[0], worlds[1].obst_a, worlds[1].obst_b)
    poses, scene, row_world, row_robot, specs = pack(worlds)
    bank.set_sensors(row_world, row_robot, specs)
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene)
    want = [r for world in worlds for r in reference(world)]
    assert all(np.array_equal(a, b) for a, b in zip(rows_of(bank), want, strict=True))
    assert len({id(s.grid) for s in bank._slots.values() if s.worlds}) == 3
    assert len(bank._slots) < 24  # the slots of grids no world shows were dropped on the way


def test_set_sensors_keeps_the_held_ranges_of_unchanged_rows(grids) -> None:
    worlds = worlds_for(51, grids)
    bank, poses, scene = build(worlds)
    bank.scan(np.ones(bank.num_rows, dtype=bool), poses, scene)
    before = rows_of(bank)
    old_world = pack(worlds)[2]
    # equal specs rebuilt per episode (new objects): nothing changes, no row is touched
    _, _, row_world, row_robot, specs = pack(worlds)
    view = bank.ranges(0)
    bank.set_sensors(row_world, row_robot, [s.model_copy() for s in specs])
    assert bank.ranges(0).base is view.base
    assert all(np.array_equal(a, b) for a, b in zip(rows_of(bank), before, strict=True))
    # world 2 resets with another robot count; the other worlds keep their rows and ranges
    worlds[2].poses = np.vstack([worlds[2].poses, [[5.0, 5.0, 0.0]]])
    worlds[2].radius = [*worlds[2].radius, 0.3]
    worlds[2].sensors = [*worlds[2].sensors, [ROUND]]
    poses, scene, row_world, row_robot, specs = pack(worlds)
    bank.set_sensors(row_world, row_robot, specs)
    kept = [s for s in range(len(old_world)) if old_world[s] != 2]
    new_rows = [s for s in range(bank.num_rows) if row_world[s] != 2]
    for s_old, s_new in zip(kept, new_rows, strict=True):
        assert np.array_equal(bank.ranges(s_new), before[s_old])
    assert np.all(bank.ranges(int(np.flatnonzero(row_world == 2)[-1])) == ROUND.range_max)


def test_add_noise_is_lidar2d_noise() -> None:
    spec = FRONT.model_copy(update={"noise_std": 0.05})
    grid = walled_grid(False, 1)
    bank = LidarBank()
    bank.bind_world(0, grid)
    bank.set_sensors([0], [0], [spec])
    pose = np.array([[3.0, 3.0, 0.4]])
    empty = Scene(np.zeros(2, dtype=np.int64), np.zeros((0, 2)), np.zeros(0),
                  np.zeros(0, dtype=np.int64), np.zeros(2, dtype=np.int64), np.zeros((0, 2)),
                  np.zeros((0, 2)), np.zeros(0, dtype=np.int64))
    bank.scan(np.ones(1, dtype=bool), pose, empty)
    bank.add_noise(0, np.random.default_rng(8))
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    want = lidar.scan(pose[0], rng=np.random.default_rng(8))
    assert np.array_equal(bank.ranges(0), want)
    assert not np.array_equal(want, lidar.scan(pose[0]))


def test_errors_name_the_problem(grids) -> None:
    bank = LidarBank()
    bank.set_sensors([1], [0], [FRONT])
    scene = Scene(np.zeros(3, dtype=np.int64), np.zeros((0, 2)), np.zeros(0),
                  np.zeros(0, dtype=np.int64), np.zeros(3, dtype=np.int64), np.zeros((0, 2)),
                  np.zeros((0, 2)), np.zeros(0, dtype=np.int64))
    with pytest.raises(SimulationError, match=r"bind_world\(1, \.\.\.\) was never called"):
        bank.scan(np.ones(1, dtype=bool), np.zeros((1, 3)), scene)
    bank.bind_world(1, grids[0])
    with pytest.raises(SimulationError, match=r"due must have shape \(1,\)"):
        bank.scan(np.ones(2, dtype=bool), np.zeros((1, 3)), scene)
    with pytest.raises(SimulationError, match="a row for every robot"):
        bank.scan(np.ones(1, dtype=bool), np.zeros((0, 3)), scene)
    bad = Scene(np.array([0, 2]), np.zeros((0, 2)), np.zeros(0), np.zeros(0, dtype=np.int64),
                np.zeros(3, dtype=np.int64), np.zeros((0, 2)), np.zeros((0, 2)),
                np.zeros(0, dtype=np.int64))
    with pytest.raises(SimulationError, match=r"scene\.circ_off must have a row per world"):
        bank.scan(np.ones(1, dtype=bool), np.ones((1, 3)), bad)
    beyond = Scene(np.array([0, 0, 5]), np.zeros((0, 2)), np.zeros(0),
                   np.zeros(0, dtype=np.int64), np.zeros(3, dtype=np.int64), np.zeros((0, 2)),
                   np.zeros((0, 2)), np.zeros(0, dtype=np.int64))
    for parallel in (False, True):
        with pytest.raises(SimulationError, match="offsets must rise within the scene's"):
            bank.scan(np.ones(1, dtype=bool), np.ones((1, 3)), beyond, parallel=parallel)
    with pytest.raises(SimulationError, match="same length"):
        bank.set_sensors([0, 1], [0], [FRONT])
    with pytest.raises(SimulationError, match="scanning robots must be finite"):
        bank.scan(np.ones(1, dtype=bool), np.full((1, 3), np.nan), scene)

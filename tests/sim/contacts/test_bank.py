"""ContactBank: every robot of every world in one call equals the one-robot tests."""

import math

import numba
import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.core.geometry import rectangle, regular_polygon
from arena.maps.grid import OccupancyGrid
from arena.scene.state import Obstacle, StaticWorld
from arena.sim.contacts import (
    ContactBank,
    Footprint,
    ObstacleIndex,
    first_agent_hit,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)
from arena.sim.contacts import bank as bank_module

FOOTPRINTS = (
    Footprint.make(None, 0.3),
    Footprint.make(rectangle(0.6, 0.4), 0.0),
    Footprint.make(np.array([[0.35, 0.0], [-0.2, 0.25], [-0.2, -0.25]]), 0.0),
    Footprint.make(regular_polygon(0.25, 6), 0.0),
)


def make_grid(seed: int, res: float, origin: tuple[float, float]) -> OccupancyGrid:
    rng = np.random.default_rng(seed)
    h, w = int(6 / res), int(6 / res)
    occ = rng.random((h, w)) < 0.03
    occ[h // 2, : w // 2] = True  # a one-cell wall
    return OccupancyGrid.from_occupied(occ, res, origin)


def make_world(seed: int, grid: OccupancyGrid) -> StaticWorld:
    rng = np.random.default_rng(100 + seed)
    ox, oy = grid.origin
    obs = tuple(
        Obstacle(
            f"o{k}",
            "box",
            np.array([ox + rng.uniform(1, 5), oy + rng.uniform(1, 5), rng.uniform(-3, 3)]),
            rectangle(*rng.uniform(0.2, 0.8, 2)) if k % 2 else regular_polygon(0.3, 5),
        )
        for k in range(int(rng.integers(0, 5)))
    )
    return StaticWorld.build(grid, obs)


GRID_A = make_grid(0, 0.1, (0.0, 0.0))
WORLDS = (
    make_world(0, GRID_A),
    make_world(1, make_grid(1, 0.05, (-3.0, 2.0))),
    make_world(2, GRID_A),  # shares world 0's grid
    make_world(3, make_grid(3, 0.25, (1.5, -1.0))),
)
ROBOTS_PER_WORLD = (2, 1, 0, 3)


def bound_bank(worlds=WORLDS, per_world=ROBOTS_PER_WORLD, seed=0):
    rng = np.random.default_rng(seed)
    bank = ContactBank()
    for w, world in enumerate(worlds):
        bank.bind_world(w, world)
    row_world = np.repeat(np.arange(len(worlds)), per_world)
    fps = [FOOTPRINTS[int(rng.integers(len(FOOTPRINTS)))] for _ in row_world]
    bank.set_robots(row_world, fps)
    return bank, row_world, fps


def random_scene(rng, worlds, row_world):
    """Poses crowded into a 2 m square of each world (contacts happen), moves, agents."""
    poses = np.empty((len(row_world), 3))
    for i, w in enumerate(row_world):
        ox, oy = worlds[w].grid.origin
        poses[i] = ox + rng.uniform(1.5, 3.5), oy + rng.uniform(1.5, 3.5), rng.uniform(-4, 4)
    previous = poses + np.c_[rng.normal(0, 0.4, (len(poses), 2)), rng.uniform(-3, 3, len(poses))]
    counts = rng.integers(0, 5, len(worlds))
    ag_off = np.r_[0, np.cumsum(counts)].astype(np.int64)
    ag_pos = np.concatenate(
        [np.zeros((0, 2))]
        + [
            np.array(worlds[w].grid.origin) + rng.uniform(1.5, 3.5, (counts[w], 2))
            for w in range(len(worlds))
        ]
    )
    ag_r = rng.uniform(0.15, 0.35, len(ag_pos))
    return poses, previous, ag_off, ag_pos, ag_r


def swept_poses(pose, previous, fp, res):
    """The sweep rule: k = ceil(d / spacing) poses, spacing max(res, radius) / 2, short turn."""
    dist = math.hypot(pose[0] - previous[0], pose[1] - previous[1])
    k = math.ceil(dist / max(res * 0.5, fp.radius * 0.5))
    if k <= 1:
        return [pose]
    dtheta = (pose[2] - previous[2] + math.pi) % (2 * math.pi) - math.pi
    return [
        np.array([*(previous[:2] + s * (pose[:2] - previous[:2])), previous[2] + s * dtheta])
        for s in np.linspace(0.0, 1.0, k + 1)[1:]
    ]


def one_by_one(worlds, row_world, fps, poses, previous, ag_off, ag_pos, ag_r):
    """The flags from the one-robot tests, indices local to each world."""
    n = len(row_world)
    wall, obstacle = np.zeros(n, bool), np.full(n, -1)
    agent, robot = np.full(n, -1), np.full(n, -1)
    for i, (w, fp) in enumerate(zip(row_world, fps, strict=True)):
        world = worlds[w]
        way = [poses[i]] if previous is None else swept_poses(poses[i], previous[i], fp,
                                                             world.grid.resolution)
        wall[i] = any(hits_grid(world.grid, fp, p) for p in way)
        obstacle[i] = first_obstacle_hit(ObstacleIndex.build(world), fp, poses[i])
        a0, a1 = ag_off[w], ag_off[w + 1]
        agent[i] = first_agent_hit(fp, poses[i], ag_pos[a0:a1], ag_r[a0:a1])
        mates = np.flatnonzero(row_world == w)
        for local, j in enumerate(mates):
            if j != i and footprints_overlap(fp, poses[i], fps[j], poses[j]):
                robot[i] = local
                break
    return wall, obstacle, agent, robot


def assert_flags_equal(got, want, rows=slice(None)):
    for name, g, e in zip(("wall", "obstacle", "agent", "robot"), got, want, strict=True):
        np.testing.assert_array_equal(g[rows], e[rows], err_msg=name)


def test_bank_equals_the_one_robot_tests_serial_and_parallel():
    bank, row_world, fps = bound_bank()
    rng = np.random.default_rng(1)
    touched = np.zeros(4, int)
    for _ in range(150):
        scene = random_scene(rng, WORLDS, row_world)
        for prev in (None, scene[1]):
            args = (scene[0], prev, *scene[2:])
            want = one_by_one(WORLDS, row_world, fps, *args)
            serial = bank.test(*args)
            assert_flags_equal(serial, want)
            assert_flags_equal(bank.test(*args, parallel=True), serial)
            touched += [want[0].sum(), (want[1] >= 0).sum(), (want[2] >= 0).sum(),
                        (want[3] >= 0).sum()]  # fmt: skip
    assert (touched > 20).all(), touched  # every kind of contact happened


def test_a_world_flags_do_not_depend_on_the_other_worlds_or_threads():
    bank, row_world, fps = bound_bank()
    rng = np.random.default_rng(2)
    for _ in range(40):
        poses, previous, ag_off, ag_pos, ag_r = random_scene(rng, WORLDS, row_world)
        full = bank.test(poses, previous, ag_off, ag_pos, ag_r, parallel=True)
        for w in range(len(WORLDS)):
            rows = row_world == w
            alone = ContactBank()
            alone.bind_world(0, WORLDS[w])
            mine = [f for f, r in zip(fps, rows, strict=True) if r]
            alone.set_robots(np.zeros(rows.sum(), np.int64), mine)
            a0, a1 = ag_off[w], ag_off[w + 1]
            single = alone.test(
                poses[rows], previous[rows], np.array([0, a1 - a0]), ag_pos[a0:a1], ag_r[a0:a1]
            )
            assert_flags_equal([f[rows] for f in full], single)
        # the other worlds move: world 0's rows keep their flags, on one thread or several
        moved = poses.copy()
        moved[row_world != 0, :2] += 0.37
        threads = numba.get_num_threads()
        try:
            numba.set_num_threads(1)
            again = bank.test(moved, previous, ag_off, ag_pos, ag_r, parallel=True)
        finally:
            numba.set_num_threads(threads)
        assert_flags_equal(again, full, rows=row_world == 0)


def test_rows_mask_leaves_the_others_untouched():
    bank, row_world, _ = bound_bank()
    scene = random_scene(np.random.default_rng(3), WORLDS, row_world)
    all_rows = bank.test(*scene)
    mask = np.array([True, False, True, False, True, True])
    part = bank.test(*scene, rows=mask)
    assert_flags_equal(part, all_rows, rows=mask)
    assert_flags_equal(bank.test(*scene, rows=mask, parallel=True), part)
    assert not part[0][~mask].any()
    for flags in part[1:]:
        assert (flags[~mask] == -1).all()


def test_rebinding_worlds_repacks_grids_and_stays_exact(monkeypatch):
    """Fresh grids every episode: the pack is compacted and flags stay those of each grid."""
    monkeypatch.setattr(bank_module, "_MIN_COMPACT_CELLS", 0)
    bank, row_world, fps = bound_bank()
    worlds = list(WORLDS)
    rng = np.random.default_rng(4)
    for episode in range(12):
        w = episode % 2
        worlds[w] = make_world(10 + episode, make_grid(10 + episode, 0.1, (0.5 * episode, 0.0)))
        bank.bind_world(w, worlds[w])
        bank.set_robots(row_world, fps)
        scene = random_scene(rng, worlds, row_world)
        assert_flags_equal(bank.test(*scene), one_by_one(worlds, row_world, fps, *scene))
    live = {id(w.grid): w.grid for w in worlds}
    live_cells = sum(g.height * g.width for g in live.values())
    # unused grids are dropped once they outnumber the used ones: the pack stays bounded
    assert set(live) <= set(bank._slots)
    assert len(bank._slots) < 12
    assert bank._used <= 2 * live_cells


def test_misuse_is_a_one_line_simulation_error():
    bank = ContactBank()
    bank.bind_world(0, WORLDS[0])
    with pytest.raises(SimulationError, match=r"world\(s\) \[1\] not bound"):
        bank.set_robots(np.array([0, 1]), FOOTPRINTS[:2])
    with pytest.raises(SimulationError, match="ascending"):
        bank.set_robots(np.array([0, -1]), FOOTPRINTS[:2])
    with pytest.raises(SimulationError, match="2 rows but 1 footprints"):
        bank.set_robots(np.array([0, 0]), FOOTPRINTS[:1])
    bank.set_robots(np.array([0, 0]), FOOTPRINTS[:2])
    no_agents = (np.array([0, 0]), np.zeros((0, 2)), np.zeros(0))
    with pytest.raises(SimulationError, match=r"poses must have shape \(2, 3\)"):
        bank.test(np.zeros((3, 3)), None, *no_agents)
    with pytest.raises(SimulationError, match=r"ag_off must have shape \(W \+ 1,\) for W >= 1"):
        bank.test(np.zeros((2, 3)), None, np.array([0]), np.zeros((0, 2)), np.zeros(0))

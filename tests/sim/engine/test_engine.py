"""Engine: worlds independent of W and of each other, resets, determinism, teleport, errors."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.sim.engine import Engine, EngineParams
from arena.sim.native2d import Native2DBackend
from tests.sim.engine.helpers import assert_same_state, driver, episodes

WALKER = {"type": "waypoint_walker"}


def _run(eng: Engine, steps: int, seed: int = 3) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(steps):
        r = eng.poses.shape[0]
        eng.step(np.column_stack([rng.uniform(0, 1, r), np.zeros(r), rng.uniform(-1, 1, r)]), 0.1)


def _start(eng: Engine, eps, offset: int = 0) -> None:
    n = eng.num_worlds
    eng.reset_worlds(range(n), eps[offset : offset + n], [driver(WALKER) for _ in range(n)],
                     [derive_rng(1, w + offset) for w in range(n)])


def test_world_results_do_not_depend_on_w_or_the_other_worlds() -> None:
    eps = episodes(["jackal"], 6)
    one, many = Engine(1), Engine(5, EngineParams(parallel_min_worlds=1))
    _start(one, eps)
    _start(many, eps)
    rng = np.random.default_rng(4)
    for k in range(30):
        cmd = np.column_stack([rng.uniform(0, 1, 5), np.zeros(5), rng.uniform(-1, 1, 5)])
        one.step(cmd[:1], 0.1)
        many.step(cmd, 0.1)
        assert_same_state(one.world_state(0), many.world_state(0), f"step {k}")


def test_reset_of_some_worlds_leaves_the_others_untouched() -> None:
    eps = episodes(["jackal"], 5)
    a, b = Engine(3), Engine(3)
    _start(a, eps)
    _start(b, eps)
    _run(a, 10)
    _run(b, 10)
    before = [b.world_state(w) for w in range(3)]
    b.reset_worlds([1], [eps[4]], [driver(WALKER)], [derive_rng(9)])
    for w in (0, 2):
        assert_same_state(b.world_state(w), before[w], f"world {w}")
    fresh = Native2DBackend()
    fresh.reset(eps[4], driver(WALKER), derive_rng(9))
    assert_same_state(b.world_state(1), fresh.state, "reset world")
    assert b.world_state(1).time == 0.0 and b.world_state(0).time == pytest.approx(1.0)


def test_same_inputs_same_results_and_a_seed_matters() -> None:
    eps = episodes(["burger"], 3)
    runs = []
    for seed in (1, 1, 2):
        eng = Engine(3)
        eng.reset_worlds(range(3), eps, [driver(WALKER) for _ in range(3)],
                         [derive_rng(seed, w) for w in range(3)])
        _run(eng, 20)
        runs.append([eng.world_state(w).agents.positions for w in range(3)])
    assert all(np.array_equal(x, y) for x, y in zip(runs[0], runs[1], strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(runs[0], runs[2], strict=True))


def test_teleport_moves_one_robot_of_one_world() -> None:
    eps = episodes(["jackal"], 3)
    eng = Engine(2)
    _start(eng, eps)
    _run(eng, 5)
    other = eng.world_state(0)
    pose = Pose2D(3.5, 3.5, 0.7)
    eng.teleport(1, 0, pose)
    assert_same_state(eng.world_state(0), other, "untouched world")
    got = eng.world_state(1)
    assert got.robots.poses[0].tolist() == [3.5, 3.5, 0.7]
    assert got.robots.twists[0].tolist() == [0.0, 0.0, 0.0]
    assert got.step == 5


def test_bad_calls_raise_simulation_errors() -> None:
    eng = Engine(2)
    eps = episodes(["jackal"], 2)
    with pytest.raises(SimulationError, match="before reset"):
        eng.step(np.zeros((0, 3)), 0.1)
    eng.reset_worlds([0], eps[:1], [None], [derive_rng(0)])
    with pytest.raises(SimulationError, match=r"worlds \[1\]"):
        eng.step(np.zeros((1, 3)), 0.1)
    eng.reset_worlds([1], eps[1:], [None], [derive_rng(1)])
    with pytest.raises(SimulationError, match=r"shape \(2, 3\)"):
        eng.step(np.zeros((1, 3)), 0.1)
    with pytest.raises(SimulationError, match="finite"):
        eng.step(np.full((2, 3), np.nan), 0.1)
    with pytest.raises(SimulationError, match="no world 2"):
        eng.reset_worlds([2], eps[:1], [None], [derive_rng(0)])
    with pytest.raises(SimulationError, match="no robot 1"):
        eng.teleport(0, 1, Pose2D(1, 1, 0))
    with pytest.raises(SimulationError, match="num_worlds"):
        Engine(0)


class _StridedPeople:
    """A driver handing out its people as strided (non-contiguous) views: plugins may."""

    def __init__(self, inner) -> None:
        self.inner = inner

    @staticmethod
    def _strided(a):
        wide = np.zeros((len(a), 3))
        wide[:, :2] = a.positions
        radii = np.repeat(a.radii, 2)
        return type(a)(a.ids, wide[:, :2], a.velocities, a.headings, radii[::2], a.kinds,
                       a.states)

    def reset(self, spawn, world, rng):
        return self._strided(self.inner.reset(spawn, world, rng))

    def step(self, robots, dt):
        return self._strided(self.inner.step(robots, dt))


def test_contacts_with_pedestrians_handed_out_as_strided_views() -> None:
    eps = episodes(["jackal"], 1, "task.obstacles.dynamic=12")
    plain, strided = Engine(1), Engine(1)
    plain.reset_worlds([0], eps, [driver(WALKER)], [derive_rng(2)])
    strided.reset_worlds([0], eps, [_StridedPeople(driver(WALKER))], [derive_rng(2)])
    assert not strided.agents[0].positions.flags.c_contiguous
    rng = np.random.default_rng(6)
    touched = 0
    for k in range(150):
        cmd = np.array([[rng.uniform(0.5, 2.0), 0.0, rng.uniform(-2.0, 2.0)]])
        plain.step(cmd, 0.1)
        strided.step(cmd, 0.1)
        assert_same_state(plain.world_state(0), strided.world_state(0), f"step {k}")
        touched += int(plain.agent[0] >= 0)
    assert touched > 0  # the pedestrian test ran on people in contact

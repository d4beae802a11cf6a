"""Episodes and lock-step runs shared by the engine tests."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arena.config.loader import load_config
from arena.core.rng import derive_rng
from arena.crowd.driver import build_driver
from arena.crowd.simulator import CrowdSimulator
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.scene.state import SimState
from arena.sim.engine import Engine, EngineParams
from arena.sim.native2d import Native2DBackend
from arena.tasks.generator import TaskGenerator

ROOM = (
    "map={type: empty, width: 7, height: 7, resolution: 0.1}",
    "task.obstacles={type: random, static: 2, dynamic: 6}",
    "task.robots.min_goal_distance=2.0",
)


def episodes(robots: Sequence[str | RobotModel], count: int, *overrides: str) -> list[Episode]:
    """``count`` episodes of a small room with obstacles and six people."""
    cfg = load_config(None, [*ROOM, *overrides])
    models = [load_robot(r) if isinstance(r, str) else r for r in robots]
    gen = TaskGenerator.from_config(cfg, models)
    return [gen.episode(i) for i in range(count)]


def driver(crowd: dict | None, pedestrians: dict | None = None) -> CrowdSimulator | None:
    """The crowd of a config block, as ``arena run`` builds it (``None``: people stand)."""
    if crowd is None:
        return None
    cfg = load_config(None, [f"crowd={crowd}", *(f"pedestrians.{k}={v}" for k, v in
                                                  (pedestrians or {}).items())])
    return build_driver(cfg.crowd, cfg.pedestrians)


def assert_same_state(a: SimState, b: SimState, where: str) -> None:
    """Bit-identical snapshots (time, robots, scans, contacts, people)."""
    assert a.time == b.time and a.step == b.step, where
    ra, rb = a.robots, b.robots
    for name in ("poses", "twists", "commands", "radii"):
        assert np.array_equal(getattr(ra, name), getattr(rb, name)), f"{where}: {name}"
    assert len(ra.scans) == len(rb.scans), where
    for sa, sb in zip(ra.scans, rb.scans, strict=True):
        assert np.array_equal(sa, sb), f"{where}: scans"
    for ma, mb in zip(ra.sensors, rb.sensors, strict=True):  # every sensor, by name
        assert list(ma) == list(mb), where
        for name in ma:
            assert np.array_equal(ma[name], mb[name]), f"{where}: sensors[{name!r}]"
    for name in ("wall", "obstacle", "agent", "robot"):
        assert np.array_equal(getattr(a.collisions, name), getattr(b.collisions, name)), (
            f"{where}: collisions.{name}"
        )
    for name in ("positions", "velocities", "headings", "radii", "kinds", "states"):
        assert np.array_equal(getattr(a.agents, name), getattr(b.agents, name)), (
            f"{where}: agents.{name}"
        )


def lock_step(
    eps: list[Episode],
    crowd: dict | None,
    *,
    pedestrians: dict | None = None,
    params: EngineParams | None = None,
    steps: int = 80,
    reset_at: int | None = 40,
    speed: float = 1.5,
) -> dict[str, bool]:
    """Run ``Engine(W)`` and one ``Native2DBackend`` per world side by side; assert equality.

    World ``w`` plays ``eps[w]``; with ``reset_at``, world 1 (if any, else 0) restarts with
    ``eps[-1]`` at that step. Returns what happened: ``collided``, ``people_moved``,
    ``states_seen`` (a social state other than 0), ``groups`` (some people walk in groups).
    """
    worlds = len(eps) - (1 if reset_at is not None else 0)
    eng = Engine(worlds, params)
    refs = [Native2DBackend(params) for _ in range(worlds)]

    def start(w: int, ep: Episode, k: int) -> None:
        eng.reset_worlds([w], [ep], [driver(crowd, pedestrians)], [derive_rng(5, w, k)])
        refs[w].reset(ep, driver(crowd, pedestrians), derive_rng(5, w, k))

    for w in range(worlds):
        start(w, eps[w], 0)
    for w in range(worlds):
        assert_same_state(eng.world_state(w), refs[w].state, f"world {w} reset")
    rng = np.random.default_rng(11)
    seen = {"collided": False, "people_moved": False, "states_seen": False, "groups": False}
    first = [eng.world_state(w).agents.positions.copy() for w in range(worlds)]
    for k in range(steps):
        if reset_at is not None and k == reset_at:
            start(min(1, worlds - 1), eps[-1], 1)
        r = eng.poses.shape[0]
        cmd = np.column_stack([
            rng.uniform(0.2, speed, r), rng.uniform(-0.5, 0.5, r), rng.uniform(-1.5, 1.5, r)
        ])
        eng.step(cmd, 0.1)
        for w in range(worlds):
            a, b = int(eng.robot_off[w]), int(eng.robot_off[w + 1])
            refs[w].step(cmd[a:b], 0.1)
            got = eng.world_state(w)
            assert_same_state(got, refs[w].state, f"world {w} step {k}")
            seen["collided"] |= bool(got.collisions.any.any())
            seen["states_seen"] |= bool(np.any(got.agents.states != 0))
            drv = eng.drivers[w]
            if isinstance(drv, CrowdSimulator):
                seen["groups"] |= bool(np.any(drv.state.group >= 0))
            if got.agents.positions.shape == first[w].shape:
                seen["people_moved"] |= bool(np.any(got.agents.positions != first[w]))
    return seen

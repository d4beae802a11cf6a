"""Behavioural contracts every plugin of a kind must meet, checked on small standard worlds."""

from __future__ import annotations

import numpy as np

from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import MapResult, MapSource
from arena.robots.presets import load_robot
from arena.sim.backend import PedestrianDriver
from arena.sim.state import RobotStates, SimState, StaticWorld
from arena.tasks.base import Task
from arena.tasks.episode import WAYPOINT_LOOP, AgentSpawn, Episode, RobotSpawn


def standard_episode(n_agents: int = 6) -> Episode:
    """A 12 x 8 m room, a jackal and a burger, pedestrians on loops (deterministic)."""
    grid = OccupancyGrid.empty(12.0, 8.0, 0.05)
    rng = np.random.default_rng(1234)
    pos = rng.uniform([3.0, 1.0], [11.0, 7.0], (n_agents, 2))
    wps = rng.uniform([1.0, 1.0], [11.0, 7.0], (n_agents, 3, 2))
    agents = AgentSpawn(
        positions=pos,
        radii=np.full(n_agents, 0.3),
        vmax=np.full(n_agents, 1.0),
        waypoints=wps,
        num_waypoints=np.full(n_agents, 3),
        waypoint_mode=np.full(n_agents, WAYPOINT_LOOP),
        kinds=np.zeros(n_agents, dtype=np.int64),
    )
    robots = (
        RobotSpawn("a", load_robot("jackal"), Pose2D(1.0, 2.0, 0.0), Pose2D(10.0, 2.0, 0.0)),
        RobotSpawn("b", load_robot("burger"), Pose2D(1.0, 6.0, 0.0), Pose2D(10.0, 6.0, 0.0)),
    )
    return Episode(0, 0, "conformance", grid, (), robots, agents, 30.0)


def _rollout(make_backend, make_driver, episode: Episode, steps: int) -> list[SimState]:
    backend = make_backend()
    states = [backend.reset(episode, make_driver(), np.random.default_rng(7))]
    cmd = np.array([[0.5, 0.0, 0.2], [0.2, 0.0, -0.5]])
    for _ in range(steps):
        states.append(backend.step(cmd, 0.1))
    return states


def check_backend(make_backend, make_driver=lambda: None, steps: int = 20) -> None:
    """A backend resets, steps, reports consistent shapes, respects limits and is deterministic."""
    ep = standard_episode()
    backend = make_backend()
    # Checked on the class: the world/state properties may rightly raise before reset().
    missing = [m for m in ("reset", "step", "world", "state") if not hasattr(type(backend), m)]
    assert not missing, f"does not implement SimulatorBackend: missing {missing}"
    s0 = backend.reset(ep, make_driver(), np.random.default_rng(7))
    n = len(ep.robots)
    assert s0.robots.poses.shape == (n, 3), "robot poses must be (r, 3)"
    assert np.allclose(s0.robots.poses, [r.start.as_array() for r in ep.robots]), "start poses"
    for spec, scan in zip((r.model.laser for r in ep.robots), s0.robots.scans, strict=True):
        assert scan.shape == (spec.num_beams,), "one range per beam"
        assert np.all((scan >= spec.range_min) & (scan <= spec.range_max)), "ranges in bounds"
    assert len(s0.agents) == len(ep.agents), "every pedestrian is reported"
    cmd = np.array([[0.5, 0.0, 0.2], [0.2, 0.0, -0.5]])
    kept = cmd.copy()
    s1 = backend.step(cmd, 0.1)
    assert np.array_equal(cmd, kept), "step must not mutate the commands"
    assert s1.time == s0.time + 0.1 and s1.step == 1, "time and step advance"
    a = _rollout(make_backend, make_driver, ep, steps)
    b = _rollout(make_backend, make_driver, ep, steps)
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x.robots.poses, y.robots.poses), "same seed, same trajectory"
        assert np.array_equal(x.agents.positions, y.agents.positions), "same seed, same crowd"
    for s in a:
        for i, spawn in enumerate(ep.robots):
            lim = spawn.model.limits()
            tw = s.robots.twists[i]
            assert lim.vx_min - 1e-9 <= tw[0] <= lim.vx_max + 1e-9, "vx within limits"
            assert abs(tw[2]) <= lim.omega_max + 1e-9, "omega within limits"
        assert np.all(np.isfinite(s.robots.poses)), "finite poses"


def check_crowd_model(make_model, steps: int = 50, dt: float = 0.1) -> None:
    """A crowd model places every agent, moves them with finite values, deterministically."""
    ep = standard_episode()
    world = StaticWorld.build(ep.grid, ep.obstacles)
    robots = RobotStates(
        ("a",),
        ("jackal",),
        np.array([[1.0, 2.0, 0.0]]),
        np.zeros((1, 3)),
        np.zeros((1, 3)),
        np.array([0.3]),
        (None,),
        (np.zeros(0),),
    )
    spawn_before = ep.agents.positions.copy()

    def run() -> list:
        model: PedestrianDriver = make_model()
        assert isinstance(model, PedestrianDriver), "does not implement PedestrianDriver"
        out = [model.reset(ep.agents, world, np.random.default_rng(3))]
        out += [model.step(robots, dt) for _ in range(steps)]
        return out

    a, b = run(), run()
    assert np.array_equal(ep.agents.positions, spawn_before), "the spawn must not be mutated"
    assert np.allclose(a[0].positions, ep.agents.positions), "agents start at their spawn"
    n = len(ep.agents)
    for s, t in zip(a, b, strict=True):
        assert s.positions.shape == (n, 2) and s.velocities.shape == (n, 2), "shapes"
        assert s.headings.shape == (n,) and s.radii.shape == (n,), "shapes"
        assert np.all(np.isfinite(s.positions)) and np.all(np.isfinite(s.velocities)), "finite"
        assert np.array_equal(s.positions, t.positions), "same seed, same motion"
    moved = np.linalg.norm(a[-1].positions - a[0].positions, axis=1)
    assert np.any(moved > 0.1), "agents with waypoints must move"


def check_map_source(source: MapSource) -> None:
    """A map source returns a valid grid, the same one for the same seed."""
    a = source.build(np.random.default_rng(5))
    b = source.build(np.random.default_rng(5))
    assert isinstance(a, MapResult), "build must return a MapResult"
    assert a.grid == b.grid, "same seed, same map"
    assert a.grid.free.any(), "a map needs free space"
    assert isinstance(a.name, str) and a.name, "a map needs a name"


def check_task(task: Task, map_result: MapResult) -> None:
    """A task samples valid episodes deterministically."""
    jackal = load_robot("jackal")

    def draw(seed: int) -> Episode:
        return task.sample(
            map_result, [jackal], index=0, seed=seed, rng=np.random.default_rng(seed)
        )

    a, b, c = draw(1), draw(1), draw(2)
    assert isinstance(a, Episode), "sample must return an Episode"
    assert a.robots[0].start == b.robots[0].start and a.robots[0].goal == b.robots[0].goal
    assert np.array_equal(a.agents.positions, b.agents.positions), "same seed, same agents"
    assert (a.robots[0].start, a.robots[0].goal) != (c.robots[0].start, c.robots[0].goal)
    for spawn in a.robots:
        for pose in (spawn.start, spawn.goal):
            assert not map_result.grid.is_occupied(pose.xy), "start and goal in free space"
    assert a.time_limit > 0

"""Behavioural contracts every plugin of a kind must meet, checked on small standard worlds."""

from __future__ import annotations

import numpy as np

from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import MapResult, MapSource
from arena.robots.presets import load_robot
from arena.scene.episode import WAYPOINT_LOOP, AgentSpawn, Episode, RobotSpawn
from arena.scene.state import RobotStates, SimState, StaticWorld


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
    _check_teleport(make_backend, make_driver, ep)


def _check_teleport(make_backend, make_driver, ep: Episode) -> None:
    """Teleport moves one robot at rest without advancing time; its scan sees the new place."""
    backend = make_backend()
    assert hasattr(type(backend), "teleport"), "does not implement SimulatorBackend.teleport"
    backend.reset(ep, make_driver(), np.random.default_rng(7))
    cmd = np.array([[0.5, 0.0, 0.2], [0.2, 0.0, -0.5]])
    for _ in range(5):
        before = backend.step(cmd, 0.1)
    target = Pose2D(6.0, 4.0, 1.0)
    s = backend.teleport(0, target)
    assert s.time == before.time and s.step == before.step, "teleport must not advance time"
    assert np.allclose(s.robots.poses[0], target.as_array()), "robot 0 is at the target pose"
    assert np.allclose(s.robots.poses[1], before.robots.poses[1]), "other robots stay"
    assert np.allclose(s.robots.twists[0], 0.0), "a teleported robot is at rest"
    assert np.allclose(backend.state.robots.poses[0], target.as_array()), "state is updated"
    spec = ep.robots[0].model.laser
    assert s.robots.scans[0].shape == (spec.num_beams,), "one range per beam after teleport"
    assert not np.array_equal(s.robots.scans[0], before.robots.scans[0]), (
        "the scan is taken at the new pose"
    )
    # Teleporting into a wall is reported as a contact.
    s_wall = backend.teleport(1, Pose2D(0.02, 0.02, 0.0))
    assert bool(s_wall.collisions.wall[1]), "a robot teleported into a wall is in contact"
    nxt = backend.step(np.zeros((2, 3)), 0.1)
    assert np.isclose(nxt.time, s.time + 0.1), "stepping continues after a teleport"


def _crowd_episode(grid: OccupancyGrid, starts: np.ndarray, waypoints: np.ndarray) -> AgentSpawn:
    n = starts.shape[0]
    return AgentSpawn(
        positions=starts,
        radii=np.full(n, 0.3),
        vmax=np.linspace(0.8, 1.3, n),
        waypoints=waypoints,
        num_waypoints=np.full(n, waypoints.shape[1]),
        waypoint_mode=np.full(n, WAYPOINT_LOOP),
        kinds=np.zeros(n, dtype=np.int64),
        groups=np.full(n, -1, dtype=np.int64),
    )


def _run_crowd(make_model, spawn: AgentSpawn, grid: OccupancyGrid, steps: int, seed: int = 3):
    from arena.crowd.driver import driver_of
    from arena.crowd.simulator import PedestrianConfig

    sim = driver_of(make_model(), PedestrianConfig(social_states=False, group_fraction=0.0))
    world = StaticWorld.build(grid)
    robots = RobotStates(
        ("r",),
        ("burger",),
        np.array([[-50.0, -50.0, 0.0]]),
        np.zeros((1, 3)),
        np.zeros((1, 3)),
        np.array([0.2]),
        (None,),
        (np.zeros(0),),
    )
    out = [sim.reset(spawn, world, np.random.default_rng(seed))]
    caps = []
    for _ in range(steps):
        out.append(sim.step(robots, 0.1))
        # a driver of its own may keep no CrowdState: then its speeds are only checked finite
        state = getattr(sim, "state", None)
        caps.append(np.inf if state is None else state.vmax * state.vmax_factor)
    return out, caps


def check_crowd_model(make_model, *, reaches_waypoints: bool = True) -> None:
    """Check a crowd model as it runs (social states off): in the crowd simulator, or alone.

    A :class:`~arena.crowd.base.DriverModel` runs as its own driver. Agents move finitely,
    within their speed caps and deterministically; they reach their waypoints in an empty room;
    and nobody walks into a wall in 1,000 steps of two opposing streams in a corridor.

    Args:
        make_model: builds a fresh model instance.
        reaches_waypoints: check that agents reach their waypoints (False only for models whose
            purpose contradicts it, e.g. the ``spinny`` demo that walks in circles).
    """
    # 1. Empty 12 x 12 m room: 8 agents cross to the opposite side and back.
    room = OccupancyGrid.empty(12.0, 12.0, 0.05)
    t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    starts = 6.0 + 4.0 * np.stack([np.cos(t), np.sin(t)], axis=1)
    goals = 6.0 - 4.0 * np.stack([np.cos(t), np.sin(t)], axis=1)
    spawn = _crowd_episode(room, starts, np.stack([goals, starts], axis=1))
    kept = (spawn.positions.copy(), spawn.waypoints.copy(), spawn.vmax.copy())
    a, caps = _run_crowd(make_model, spawn, room, 300)
    b, _ = _run_crowd(make_model, spawn, room, 300)
    assert np.array_equal(spawn.positions, kept[0]), "the spawn positions must not be mutated"
    assert np.array_equal(spawn.waypoints, kept[1]), "the spawn waypoints must not be mutated"
    assert np.array_equal(spawn.vmax, kept[2]), "the spawn speeds must not be mutated"
    for s, t_, cap in zip(a[1:], b[1:], caps, strict=True):
        assert np.all(np.isfinite(s.positions)), "positions must stay finite"
        assert np.all(np.isfinite(s.velocities)), "velocities must stay finite"
        speed = np.hypot(s.velocities[:, 0], s.velocities[:, 1])
        assert np.all(speed <= cap + 1e-9), "speed must not exceed vmax * vmax_factor"
        assert np.array_equal(s.positions, t_.positions), "same seed, same trajectory"
    if reaches_waypoints:
        pos = np.array([s.positions for s in a])  # (steps, n, 2)
        d = np.linalg.norm(pos - goals[None], axis=2).min(axis=0)
        assert np.all(d < 0.6), (
            f"agents must reach their waypoints; closest approach {d.max():.2f} m"
        )
    # 2. Corridor 20 x 3 m: two opposing streams for 1,000 steps; nobody enters a wall.
    occ = np.zeros((80, 400), dtype=bool)
    occ[:10, :] = occ[-10:, :] = True  # 0.5 m thick walls, 3 m free
    occ[:, :4] = occ[:, -4:] = True
    corridor = OccupancyGrid.from_occupied(occ, 0.05)
    ys = np.array([1.0, 1.6, 2.2, 2.8, 1.3, 2.5])
    left = np.stack([np.full(3, 1.5), ys[:3]], axis=1)
    right = np.stack([np.full(3, 18.5), ys[3:]], axis=1)
    starts = np.concatenate([left, right])
    goals = starts.copy()
    goals[:3, 0], goals[3:, 0] = 18.5, 1.5  # walk to the far end at the same height
    spawn = _crowd_episode(corridor, starts, np.stack([goals, starts], axis=1))
    c, _ = _run_crowd(make_model, spawn, corridor, 1000)
    for s in c:
        assert not np.any(corridor.is_occupied(s.positions)), "an agent entered a wall"


def check_map_source(source: MapSource) -> None:
    """A map source returns a valid grid, the same one for the same seed."""
    a = source.build(np.random.default_rng(5))
    b = source.build(np.random.default_rng(5))
    assert isinstance(a, MapResult), "build must return a MapResult"
    assert a.grid == b.grid, "same seed, same map"
    assert a.grid.free.any(), "a map needs free space"
    assert isinstance(a.name, str) and a.name, "a map needs a name"


def check_task_mode(
    role: str,
    spec: dict,
    map_spec: dict | None = None,
    *,
    varies_with_seed: bool = True,
    episodes: int = 3,
) -> None:
    """A task mode (or module) yields valid episodes deterministically.

    Builds a :class:`~arena.tasks.generator.TaskGenerator` with ``spec`` in ``role`` (the
    other roles at their defaults, with few obstacles) and checks: same seed → same episodes
    (digests), another seed → other episodes (unless ``varies_with_seed`` is False), robots
    start and end with their body clear of walls, obstacles and people inside the map's free
    space, positive time limits, and that ``next_goal`` answers a goal in free space or ``None``.
    """
    from arena.scene.episode import episode_digest
    from arena.tasks.config import TaskConfig
    from arena.tasks.generator import TaskGenerator
    from arena.tasks.world import WorldSampler

    jackal = load_robot("jackal")
    blocks: dict = {"obstacles": {"type": "random", "static": 2, "dynamic": 3}}
    if role == "modules":
        blocks["modules"] = [spec]
    else:
        blocks[role] = spec
    cfg = TaskConfig.model_validate(blocks)
    map_spec = map_spec or {"type": "empty", "width": 16.0, "height": 12.0}

    def make(seed: int) -> TaskGenerator:
        return TaskGenerator(cfg, map_spec=map_spec, robots=[jackal], seed=seed)

    a, b, c = make(1), make(1), make(2)
    eps = [a.episode(i) for i in range(episodes)]
    assert [episode_digest(e) for e in eps] == [
        episode_digest(b.episode(i)) for i in range(episodes)
    ], "same seed, same episodes"
    if varies_with_seed:
        assert [episode_digest(e) for e in eps] != [
            episode_digest(c.episode(i)) for i in range(episodes)
        ], "another seed, other episodes"
    for ep in eps:
        assert isinstance(ep, Episode)
        assert ep.time_limit > 0 and ep.goal_radius > 0
        world = WorldSampler(ep.grid, ep.obstacles)
        for spawn in ep.robots:
            for pose in (spawn.start, spawn.goal):
                d = world.clearance(pose.xy[None])[0]
                assert d >= spawn.model.radius - 1e-9, f"robot body clear of walls ({d:.3f} m)"
        if len(ep.agents):
            assert np.all(world.wall_distance(ep.agents.positions) > 0), "people in free space"
        runtime = a.runtime(ep)
        rng = np.random.default_rng(0)
        nxt = runtime.ctx.robot_mode.next_goal(runtime.ctx, 0, ep.robots[0].goal, rng)
        assert nxt is None or isinstance(nxt, Pose2D)
        if nxt is not None:
            assert world.wall_distance(nxt.xy[None])[0] > 0, "next goal in free space"
        a.feedback(ep.index, "success")

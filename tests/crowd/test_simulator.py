import numpy as np
import pytest

from arena.crowd.integrator import guard_walls
from arena.crowd.models.walker import WaypointWalker
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig, form_groups, robot_view
from arena.crowd.state import SocialState, StartupMode
from arena.crowd.walls import WallIndex, grid_wall_segments
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import WAYPOINT_LOOP, WAYPOINT_RANDOM, AgentSpawn
from arena.scene.state import Obstacle, RobotStates, StaticWorld

WORLD = StaticWorld.build(OccupancyGrid.empty(20, 20, 0.1))
NO_ROBOTS = RobotStates(
    (), (), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), (), ()
)
PLAIN = PedestrianConfig(social_states=False, group_fraction=0.0)


def robots_at(xy, twist=(0.0, 0.0, 0.0), theta=0.0):
    return RobotStates(
        ("r",),
        ("burger",),
        np.array([[*xy, theta]]),
        np.array([twist]),
        np.zeros((1, 3)),
        np.array([0.2]),
        (None,),
        (np.zeros(0),),
    )


def spawn(mode=WAYPOINT_LOOP, n=4, k=3, seed=0, **extra):
    rng = np.random.default_rng(seed)
    return AgentSpawn(
        positions=rng.uniform(3, 17, (n, 2)),
        radii=np.full(n, 0.3),
        vmax=rng.uniform(0.5, 1.5, n),
        waypoints=rng.uniform(3, 17, (n, k, 2)),
        num_waypoints=np.full(n, k),
        waypoint_mode=np.full(n, mode),
        kinds=np.zeros(n, dtype=np.int64),
        **extra,
    )


def run(sp, steps=400, seed=1, dt=0.1, config=PLAIN, robots=NO_ROBOTS, model=None):
    sim = CrowdSimulator(model or WaypointWalker(), config)
    states = [sim.reset(sp, WORLD, np.random.default_rng(seed))]
    for _ in range(steps):
        states.append(sim.step(robots, dt))
    return sim, states


def test_speed_capped_and_acceleration_bounded():
    sp = spawn()
    _, states = run(sp)
    v = np.array([s.velocities for s in states])
    assert np.all(np.linalg.norm(v, axis=2) <= sp.vmax + 1e-9)
    acc = np.linalg.norm(np.diff(v, axis=0), axis=2) / 0.1
    assert np.all(acc <= WaypointWalker.Params().max_acceleration + 1e-6)


def boxed_room(n, size, seed=0):
    """``n`` people (0.25 m) in a walled ``size`` m square room with two boxes.

    Everyone starts clear of walls, boxes and each other and loops through 4 random waypoints.
    Returns ``(world, spawn)``.
    """
    from arena.core.geometry import rectangle
    from arena.crowd.clearance import crowd_clearance

    occ = np.zeros((round(size / 0.1),) * 2, dtype=bool)
    occ[:3] = occ[-3:] = occ[:, :3] = occ[:, -3:] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    boxes = tuple(
        Obstacle(f"box{k}", "box", np.array([x * size, y * size, 0.3]), rectangle(1.0, 0.8))
        for k, (x, y) in enumerate([(0.3, 0.5), (0.7, 0.4)])
    )
    world = StaticWorld.build(grid, boxes)
    clear = crowd_clearance(grid, [b.polygon for b in boxes])
    rng = np.random.default_rng(seed)
    pts: list[np.ndarray] = []
    while len(pts) < n:
        p = rng.uniform(0.8, size - 0.8, 2)
        if clear[int(p[1] / 0.1), int(p[0] / 0.1)] > 0.5 and all(
            np.hypot(*(p - q)) > 0.55 for q in pts
        ):
            pts.append(p)
    sp = AgentSpawn(
        positions=np.array(pts),
        radii=np.full(n, 0.25),
        vmax=rng.uniform(0.6, 1.6, n),
        waypoints=rng.uniform(0.8, size - 0.8, (n, 4, 2)),
        num_waypoints=np.full(n, 4),
        waypoint_mode=np.full(n, WAYPOINT_LOOP),
        kinds=np.zeros(n, dtype=np.int64),
    )
    return world, sp


def assert_speed_cap_holds_exactly(model, n, size, steps, config=PLAIN):
    """Every agent, every step: ``sqrt(vx² + vy²) ≤ vmax · vmax_factor``, no tolerance."""
    from arena.crowd.base import CROWD_MODELS

    world, sp = boxed_room(n, size)
    sim = CrowdSimulator(CROWD_MODELS.build(model), config)
    sim.reset(sp, world, np.random.default_rng(1))
    over, worst = 0, 0.0
    for _ in range(steps):
        sim.step(NO_ROBOTS, 0.1)
        s = sim.state
        vx, vy = s.velocities[:, 0], s.velocities[:, 1]
        excess = np.sqrt(vx * vx + vy * vy) - s.vmax * s.vmax_factor  # the integrator's formula
        over += int((excess > 0.0).sum())
        worst = max(worst, float(excess.max()))
    assert over == 0, f"{over} agent-steps over the cap, by up to {worst:.3g} m/s"
    assert worst > -1e-9  # someone walks at the cap: the test did reach it


@pytest.mark.parametrize("model", ["orca", "rvo2", "pysocial"])
def test_speed_cap_holds_exactly_in_a_dense_room_with_boxes(model):
    # ORCA ignores walls, so the wall guard pushes people out of corners: those push-outs used to
    # make 16 agent-steps here faster than the cap (by up to 1.1 mm/s), and rounding others.
    assert_speed_cap_holds_exactly(model, 100, 10.0, 1000)


@pytest.mark.slow
def test_speed_cap_holds_exactly_for_orca_with_1000_people():
    # The size: 1,000 people, 3,000 steps (13 agent-steps over the cap before).
    assert_speed_cap_holds_exactly("orca", 1000, 32.0, 3000)


def test_cap_speed_is_exact_and_keeps_the_direction():
    from arena.crowd.integrator import cap_speed

    rng = np.random.default_rng(0)
    v = rng.normal(size=(20_000, 2)) * 10.0 ** rng.uniform(-3, 3, (20_000, 1))
    cap = np.abs(rng.normal(size=20_000)) * 10.0 ** rng.uniform(-3, 3, 20_000)
    cap[:100] = 0.0
    for (vx, vy), c in zip(v, cap, strict=True):
        x, y = cap_speed(vx, vy, c)
        norm = np.sqrt(x * x + y * y)
        if np.sqrt(vx * vx + vy * vy) <= c:
            assert (x, y) == (vx, vy)  # within the cap: untouched
            continue
        assert norm <= c
        assert norm >= c * (1 - 1e-14)  # only rounding below the cap
        assert abs(x * vy - y * vx) <= 1e-12 * abs(vx * vx + vy * vy)  # same direction
        assert x * vx + y * vy >= 0.0


def test_loop_mode_visits_waypoints_in_order_with_tolerant_switch():
    sp = spawn(n=1, k=3)
    _, states = run(sp, steps=2000)
    pos = np.array([s.positions[0] for s in states])
    visits = []
    for p in pos:
        d = np.linalg.norm(sp.waypoints[0] - p, axis=1)
        j = int(np.argmin(d))
        if d[j] < PLAIN.waypoint_tolerance + 0.05 and (not visits or visits[-1] != j):
            visits.append(j)
    assert visits[:6] == [0, 1, 2, 0, 1, 2]
    # The tolerant switch means the agent never stops at or circles its waypoint: it keeps
    # walking (only slowing in sharp turns) at its preferred speed most of the time.
    speeds = np.linalg.norm([s.velocities[0] for s in states[50:]], axis=1)
    assert speeds.min() > 0.03
    assert np.median(speeds) == pytest.approx(sp.vmax[0], rel=1e-6)


def test_random_mode_deterministic_per_seed():
    sp = spawn(WAYPOINT_RANDOM, n=6, k=4)
    _, a = run(sp, seed=5)
    _, b = run(sp, seed=5)
    _, c = run(sp, seed=6)
    assert all(np.array_equal(x.positions, y.positions) for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x.positions, y.positions) for x, y in zip(a, c, strict=True))


def test_startup_modes():
    n = 3
    sp = spawn(
        n=n,
        startup_mode=np.array(
            [StartupMode.DEFAULT, StartupMode.WAIT_TIMER, StartupMode.TRIGGER_ZONE]
        ),
        wait_time=np.array([0.0, 2.0, 0.0]),
        trigger_radius=np.array([0.0, 0.0, 2.0]),
    )
    # A robot far from agent 2 first.
    far = robots_at((-50.0, -50.0))
    _, states = run(sp, steps=40, robots=far)
    moved = [np.linalg.norm(states[k].positions - sp.positions, axis=1) for k in (15, 40)]
    assert moved[0][0] > 0.1  # default: at once
    assert moved[0][1] == 0.0 and moved[1][1] > 0.1  # timer: after 2 s
    assert moved[1][2] == 0.0  # trigger zone: robot never came
    near = robots_at(tuple(sp.positions[2] + [1.0, 0.0]))
    _, states = run(sp, steps=5, robots=near)
    assert np.linalg.norm(states[-1].positions[2] - sp.positions[2]) > 0.0


def test_group_members_head_for_the_leaders_waypoint():
    sp = spawn(n=3, k=2, groups=np.array([0, 0, -1]))
    sim, states = run(sp, steps=300)
    s = sim.state
    assert s.leader.tolist() == [0, 0, 2]
    lead_wp = s.current_waypoints[0]
    d = np.linalg.norm(s.destinations[1] - lead_wp)
    assert d == pytest.approx(PLAIN.group_offset)
    assert np.linalg.norm(states[-1].positions[1] - states[-1].positions[0]) < 3.0


def test_form_groups():
    rng = np.random.default_rng(0)
    pos = rng.uniform(0, 10, (40, 2))
    cfg = PedestrianConfig(group_fraction=0.5, max_group_size=3, group_radius=3.0)
    g = form_groups(pos, cfg, np.random.default_rng(1))
    assert np.array_equal(g, form_groups(pos, cfg, np.random.default_rng(1)))
    ids, counts = np.unique(g[g >= 0], return_counts=True)
    assert counts.min() >= 2 and counts.max() <= 3
    assert 0.4 * 40 <= (g >= 0).sum() <= 0.5 * 40 + 2
    for gid in ids:  # members within the group radius of each other's seed
        m = pos[g == gid]
        assert np.max(np.linalg.norm(m[:, None] - m[None], axis=2)) < 2 * cfg.group_radius


def test_elders_walk_slower_and_states_reported():
    sp = spawn(n=2)
    sp = AgentSpawn(
        sp.positions,
        sp.radii,
        np.array([1.0, 1.0]),
        sp.waypoints,
        sp.num_waypoints,
        sp.waypoint_mode,
        np.array([0, 1]),
    )
    sim, states = run(sp, steps=5)
    assert sim.state.vmax.tolist() == [1.0, pytest.approx(0.7)]
    assert np.all(states[-1].states == SocialState.WALKING)


def test_robot_view_world_velocity():
    v = robot_view(robots_at((1.0, 2.0), twist=(1.0, 0.5, 0.0), theta=np.pi / 2))
    assert np.allclose(v.velocities[0], [-0.5, 1.0])
    assert np.allclose(v.positions[0], [1.0, 2.0])


def test_wall_guard_never_crosses_and_keeps_clearance():
    grid = OccupancyGrid.empty(10, 10, 0.1)
    idx = WallIndex(*grid_wall_segments(grid))
    rng = np.random.default_rng(3)
    p0 = rng.uniform(1, 9, (500, 2))
    p1 = p0 + rng.normal(0, 4.0, (500, 2))  # wild moves, many through the outer walls
    out = guard_walls(idx, p0, p1, np.full(500, 0.15))
    lo, hi = 0.1 + 0.15 - 1e-9, 9.9 - 0.15 + 1e-9
    assert np.all((out >= lo) & (out <= hi))
    inside = np.all((p1 > 0.25) & (p1 < 9.75), axis=1)
    assert np.allclose(out[inside], p1[inside])  # moves that stay clear are untouched


def test_inputs_not_mutated():
    sp = spawn()
    before = (sp.positions.copy(), sp.waypoints.copy())
    run(sp, steps=20)
    assert np.array_equal(sp.positions, before[0]) and np.array_equal(sp.waypoints, before[1])


def test_compiled_integrator_matches_guard_reference():
    from arena.crowd.integrator import integrate
    from arena.maps.distance import clearance_map

    occ = np.zeros((100, 100), dtype=bool)
    occ[:, 50] = True  # a thin wall through the middle
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    a, b = grid_wall_segments(grid)
    idx = WallIndex(a, b)
    rng = np.random.default_rng(7)
    n = 400
    p0 = rng.uniform(0.5, 9.5, (n, 2))
    p0 = p0[~grid.is_occupied(p0) & (np.abs(p0[:, 0] - 5.05) > 0.3)]
    n = len(p0)
    acc = rng.normal(0, 30.0, (n, 2))
    vel = rng.normal(0, 1.0, (n, 2))
    vmax = np.full(n, 2.0)
    clear = np.full(n, 0.15)
    dt = 0.5
    active = rng.random(n) < 0.9
    new_p, new_v = integrate(
        idx,
        clearance_map(grid),
        grid.origin,
        grid.resolution,
        p0,
        vel,
        acc,
        False,
        active,
        vmax,
        clear,
        dt,
    )
    v = vel + acc * dt
    v[~active] = 0
    sp = np.hypot(*v.T)
    v *= np.minimum(1.0, vmax / np.maximum(sp, 1e-12))[:, None]
    ref = guard_walls(idx, p0, p0 + v * dt, clear)
    assert np.allclose(new_p, ref, atol=1e-12)
    assert np.allclose(new_v, (ref - p0) / dt, atol=1e-12)
    # Nobody changed side of the middle wall.
    assert np.array_equal(new_p[:, 0] < 5.0, p0[:, 0] < 5.0)
    assert np.all(np.hypot(*new_v.T) <= vmax * (1 + 1e-9) + 1e-9)


def test_grid_walls_are_cached_per_map():
    """Same map: the same read-only arrays; another occupancy: traced again."""
    from arena.crowd.simulator import episode_segments
    from arena.crowd.walls import grid_walls, world_segments

    occ = np.zeros((30, 40), dtype=bool)
    occ[10:20, 5:8] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    a, b = grid_walls(grid)
    ra, rb = grid_wall_segments(grid)
    assert np.array_equal(a, ra) and np.array_equal(b, rb)
    assert not a.flags.writeable
    assert grid_walls(OccupancyGrid.from_occupied(occ.copy(), 0.1))[0] is a  # equal map
    occ[0:3, 0:3] = True
    a2, _ = grid_walls(OccupancyGrid.from_occupied(occ, 0.1))
    assert a2 is not a and not np.array_equal(a2, a)
    world = StaticWorld.build(OccupancyGrid.from_occupied(occ, 0.1))
    for got, want in zip(episode_segments(world), world_segments(world), strict=True):
        assert got.tobytes() == want.tobytes()


# -- the compiled steps against the NumPy expressions they replace (to the bit) ----------------
def test_route_kernels_are_the_numpy_expressions():
    from arena.crowd.simulator import _arrivals, _destinations

    rng = np.random.default_rng(3)
    n, k = 50, 4
    pos = rng.uniform(0, 10, (n, 2))
    wps = rng.uniform(0, 10, (n, k, 2))
    idx = rng.integers(0, k, n)
    wps[np.arange(10), idx[:10]] = pos[:10] + rng.uniform(-0.6, 0.6, (10, 2))  # near: arrive
    leader = np.arange(n)
    leader[[5, 6, 30]] = [4, 4, 29]
    members = np.flatnonzero(leader != np.arange(n))
    offsets = rng.normal(0, 1, (members.size, 2))
    started = rng.random(n) < 0.8
    radii = rng.uniform(0.2, 0.7, n)
    radii[7] = np.nan
    arrived, dest = np.empty(n, dtype=bool), np.empty((n, 2))
    _arrivals(pos, wps, idx, leader, started, radii, 0.5, members, offsets, arrived, dest)
    rows = np.arange(n)
    target = wps[rows, idx]
    tol = np.maximum(0.5, radii)
    want = (leader == rows) & started & (np.hypot(*(pos - target).T) < tol)
    np.testing.assert_array_equal(arrived, want)
    assert want[:10].any()
    wp = target.copy()
    wp[members] = wp[leader[members]] + offsets
    assert dest.tobytes() == wp.tobytes()
    again = np.empty((n, 2))
    _destinations(wps, idx, leader, members, offsets, again)
    assert again.tobytes() == wp.tobytes()


def test_robot_view_and_headings_are_the_numpy_expressions():
    from arena.crowd.simulator import _face_motion

    rng = np.random.default_rng(4)
    poses = rng.uniform(-5, 5, (3, 3))
    twists = rng.normal(0, 1, (3, 3))
    zeros = np.zeros((3, 3))
    names, kinds, radii = ("a", "b", "c"), ("burger",) * 3, np.full(3, 0.2)
    robots = RobotStates(names, kinds, poses, twists, zeros, radii, (None,) * 3, (zeros[0],) * 3)
    view = robot_view(robots)
    th = poses[:, 2]
    c, s = np.cos(th), np.sin(th)
    vx, vy = twists[:, 0], twists[:, 1]
    want = np.stack([c * vx - s * vy, s * vx + c * vy], axis=1)
    assert view.velocities.tobytes() == want.tobytes()
    assert view.positions.tobytes() == poses[:, :2].copy().tobytes()
    assert view.headings.tobytes() == th.copy().tobytes()
    v = rng.normal(0, 1e-3, (40, 2))
    heads = rng.uniform(-3, 3, 40)
    angles = np.arctan2(v[:, 1], v[:, 0])
    want_h = np.where(np.hypot(v[:, 0], v[:, 1]) > 1e-3, angles, heads)
    got_h = np.empty(40)
    _face_motion(v, angles, heads, got_h)
    assert got_h.tobytes() == want_h.tobytes()


def test_integrate_factors_are_the_premultiplied_arrays():
    from arena.crowd.integrator import integrate
    from arena.maps.distance import clearance_map

    occ = np.zeros((60, 60), dtype=bool)
    occ[:, 30] = occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    idx = WallIndex(*grid_wall_segments(grid))
    rng = np.random.default_rng(8)
    n = 200
    pos = rng.uniform(0.3, 5.7, (n, 2))
    vel, acc = rng.normal(0, 1, (n, 2)), rng.normal(0, 20, (n, 2))
    vmax, factor = rng.uniform(0.5, 2, n), rng.choice([0.0, 0.5, 1.0], n)
    radii = rng.uniform(0.1, 0.4, n)
    active = rng.random(n) < 0.9
    cmap = clearance_map(grid)
    args = (idx, cmap, grid.origin, grid.resolution, pos, vel, acc, False, active)
    got = integrate(*args, vmax, radii, 0.2, vmax_factor=factor, clearance_scale=0.8)
    want = integrate(*args, vmax * factor, 0.8 * radii, 0.2)
    assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()


# -- per-map caches of the reset (each against the computation it replaces, to the bit) ---------
def _random_polygons(rng, grid, k):
    """``k`` convex polygons anywhere on (and partly off) ``grid``, some tiny, some large."""
    lo = np.array(grid.origin)
    hi = lo + np.array([grid.width, grid.height]) * grid.resolution
    polys = []
    for _ in range(k):
        c = rng.uniform(lo - 0.5, hi + 0.5)
        ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, int(rng.integers(3, 7))))
        r = rng.uniform(0.02, 0.3 * float(np.min(hi - lo)))
        polys.append(c + r * np.stack([np.cos(ang), np.sin(ang)], axis=1))
    return polys


def test_crowd_clearance_is_the_full_distance_transform():
    """The map's cached clearance lowered near each obstacle == the transform of the union."""
    from arena.crowd.clearance import crowd_clearance
    from arena.maps.distance import clearance_map
    from arena.maps.raster import polygon_mask

    rng = np.random.default_rng(3)
    for trial in range(12):
        h, w = int(rng.integers(20, 90)), int(rng.integers(20, 90))
        occ = rng.random((h, w)) < (0.0 if trial == 0 else 0.02)  # one map with no walls at all
        occ[int(rng.integers(h)), :] = trial % 2 == 1  # a wall across, on some maps
        grid = OccupancyGrid.from_occupied(occ, 0.05 + 0.05 * (trial % 3), origin=(-1.0, 2.0))
        for k in (0, 1, 3, 6):
            polys = _random_polygons(rng, grid, k)
            blocked = grid.occupied | polygon_mask(grid, polys) if polys else grid.occupied
            want = clearance_map(grid, blocked)
            got = crowd_clearance(grid, polys)
            assert got.tobytes() == want.tobytes()
            assert got.flags.writeable
            got[:] = -1.0  # a new array per episode: writing to it leaves the cache intact
            assert crowd_clearance(grid, polys).tobytes() == want.tobytes()


def test_crowd_clearance_cache_follows_the_map():
    """Another grid (other occupancy, same shape) is computed afresh, not served the old map."""
    from arena.crowd.clearance import crowd_clearance
    from arena.maps.distance import clearance_map

    occ = np.zeros((40, 50), dtype=bool)
    first = OccupancyGrid.from_occupied(occ, 0.1)
    assert crowd_clearance(first, []).tobytes() == clearance_map(first).tobytes()
    occ[10:30, 20:23] = True
    second = OccupancyGrid.from_occupied(occ, 0.1)
    got = crowd_clearance(second, [])
    assert got.tobytes() == clearance_map(second).tobytes()
    assert got.tobytes() != crowd_clearance(first, []).tobytes()


def test_simulator_reset_uses_this_episodes_obstacles():
    """Two episodes on one map with different obstacles: each gets its own clearance map."""
    from arena.maps.distance import clearance_map
    from arena.maps.raster import polygon_mask

    grid = OccupancyGrid.empty(20, 20, 0.1)
    sim = CrowdSimulator(WaypointWalker(), PLAIN)
    for x in (5.0, 12.0):
        box = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        ob = Obstacle("box", "cuboid", np.array([x, 10.0, 0.3]), box)
        world = StaticWorld.build(grid, (ob,))
        sim.reset(spawn(), world, np.random.default_rng(0))
        want = clearance_map(grid, grid.occupied | polygon_mask(grid, [ob.polygon]))
        assert sim._clearance.tobytes() == want.tobytes()


def test_extended_wall_index_is_the_index_of_all_segments():
    """Map walls indexed once, obstacle edges appended == indexing every segment at once."""
    from arena.crowd.simulator import episode_segments

    rng = np.random.default_rng(4)
    occ = rng.random((40, 60)) < 0.03
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    sim = CrowdSimulator(WaypointWalker(), PLAIN)
    walls = WallIndex(*grid_wall_segments(grid))
    for k in (0, 1, 3):
        box = np.array([[-0.6, -0.2], [0.6, -0.2], [0.6, 0.2], [-0.6, 0.2]])
        obs = tuple(
            Obstacle(f"o{i}", "cuboid", np.r_[rng.uniform(1, 5, 2), rng.uniform(-3, 3)], box)
            for i in range(k)
        )
        world = StaticWorld.build(grid, obs)
        sim.reset(spawn(), world, np.random.default_rng(0))
        want = WallIndex(*episode_segments(world))
        for got in (walls.extended(world.segments_a, world.segments_b), sim._wall_index):
            for name in ("a", "b", "owner"):
                assert getattr(got, name).tobytes() == getattr(want, name).tobytes()
            assert got.half == want.half and len(got) == len(want)
            gc, wc = got._cells, want._cells
            assert gc.origin.tobytes() == wc.origin.tobytes() and gc.shape == wc.shape
            np.testing.assert_array_equal(gc.order, wc.order)
            np.testing.assert_array_equal(gc.starts, wc.starts)

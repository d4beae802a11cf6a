"""ORCA / RVO2 crowd models: reference runs against the C++ RVO2 library (pyrvo) and behaviour.

Our side is driven the way the crowd simulator drives a ``velocity`` model: each step a
:class:`CrowdFrame` with the cell-list neighbours within ``neighbor_cutoff()``, the velocities
from ``compute()``, then ``p += v·dt``. pyrvo gets the same preferred velocity
(:func:`preferred_velocities` of its own positions) and the same parameters.
"""

import numpy as np
import pyrvo  # the RVO2 reference, a test extra: its absence must fail, not skip
import pytest
from pydantic import ValidationError

from arena.crowd.base import CROWD_MODELS, CrowdFrame, RobotView
from arena.crowd.models.orca.model import OrcaModel, orca_velocities, preferred_velocities
from arena.crowd.models.orca.obstacles import Obstacles
from arena.crowd.models.rvo2 import Rvo2Model, counter_clockwise, world_polygons
from arena.crowd.neighbors import find_neighbors
from arena.crowd.state import CrowdState
from arena.crowd.walls import grid_wall_segments, world_segments
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle, StaticWorld

DT = 0.1
RADIUS = 0.3
VMAX = 1.0
# RVO2-example-like agent parameters, scaled to pedestrians.
REF = {"neighbor_dist": 10.0, "max_neighbors": 10, "time_horizon": 5.0}
REF_OBST = 5.0
# The figures README.md quotes ("checked against"), asserted at those figures: largest position
# difference from pyrvo (RVO2 C++) after 100 steps (m).
README_ORCA_ERR = 0.5e-3
README_RVO2_ERR = 0.3e-3

# Obstacle layouts. The centre post's line crosses the two bars, so RVO2's obstacle tree
# splits them: 5 segments become 14 vertices.
SEGMENTS = [
    ((-1.5, 2.0), (1.5, 2.0)),
    ((-1.5, -2.0), (1.5, -2.0)),
    ((3.5, -1.0), (3.5, 1.0)),
    ((-3.5, -1.0), (-3.5, 1.0)),
    ((0.0, -0.5), (0.0, 0.5)),
]


def box(x0, y0, x1, y1):
    """Counter-clockwise rectangle, as RVO2 expects polygons."""
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


POLYGONS = [  # three blocks (RVO2's Blocks example, scaled) and a non-convex L
    box(-3.0, 1.0, -1.0, 3.0),
    box(1.0, 1.0, 3.0, 3.0),
    box(-3.0, -3.0, -1.0, -1.0),
    np.array([[1.0, -3.0], [3.0, -3.0], [3.0, -2.0], [2.0, -2.0], [2.0, -1.0], [1.0, -1.0]]),
]


# -- helpers ------------------------------------------------------------------------------------
def circle(n, radius, jitter=0.05, seed=0):
    """Agents on a circle, goals antipodal; a small deterministic jitter breaks exact ties."""
    a = 2 * np.pi * np.arange(n) / n
    p = radius * np.stack([np.cos(a), np.sin(a)], axis=1)
    p += np.random.default_rng(seed).uniform(-jitter, jitter, (n, 2))
    return p, -p


def make_state(pos, goals, radius=RADIUS, vmax=VMAX):
    n = len(pos)
    spawn = AgentSpawn(
        positions=np.array(pos, dtype=np.float64),
        radii=np.broadcast_to(np.asarray(radius, dtype=np.float64), (n,)).copy(),
        vmax=np.broadcast_to(np.asarray(vmax, dtype=np.float64), (n,)).copy(),
        waypoints=np.array(goals, dtype=np.float64)[:, None, :],
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
    )
    return CrowdState.from_spawn(spawn)


def step(model, state, goals, *, walls=None, robots=None, active=None, rng=None):
    """One simulator-style step: frame → compute → v, p += v·dt. Returns the velocities."""
    n = len(state)
    wa, wb = walls if walls is not None else (np.zeros((0, 2)), np.zeros((0, 2)))
    frame = CrowdFrame(
        state=state,
        destinations=np.asarray(goals, dtype=np.float64),
        active=np.ones(n, dtype=bool) if active is None else active,
        robots=robots if robots is not None else RobotView.empty(),
        walls_a=wa,
        walls_b=wb,
        neighbors=find_neighbors(state.positions, model.neighbor_cutoff()),
        dt=DT,
        rng=rng if rng is not None else np.random.default_rng(0),
    )
    out = model.compute(frame)
    assert out.velocities is not None and out.velocities.shape == (n, 2)
    state.velocities = out.velocities
    state.positions = state.positions + out.velocities * DT
    return out.velocities


def walls_of(segments):
    seg = np.array(segments, dtype=np.float64)
    return seg[:, 0].copy(), seg[:, 1].copy()


def pyrvo_sim(pos, *, polygons=(), time_horizon_obst=REF_OBST):
    sim = pyrvo.RVOSimulator(
        DT,
        REF["neighbor_dist"],
        REF["max_neighbors"],
        REF["time_horizon"],
        time_horizon_obst,
        RADIUS,
        VMAX,
    )
    for p in pos:
        sim.add_agent((float(p[0]), float(p[1])))
    for poly in polygons:
        sim.add_obstacle([(float(x), float(y)) for x, y in poly])
    sim.process_obstacles()
    return sim


def pyrvo_positions(sim):
    return np.array([sim.get_agent_position(i).to_tuple() for i in range(sim.get_num_agents())])


def pyrvo_step(sim, goals):
    """The RVO2 examples' loop: preferred velocity from the current positions, then doStep."""
    pos = pyrvo_positions(sim)
    pref = preferred_velocities(pos, goals, np.full(len(pos), VMAX), 1.0)
    for i, v in enumerate(pref):
        sim.set_agent_pref_velocity(i, (float(v[0]), float(v[1])))
    sim.do_step()
    return pref


def segment_crossings(p0, p1, a, b):
    """Whether each move p0 → p1 ``(n, 2)`` properly crosses any segment a → b ``(s, 2)``."""

    def cross(o, u, v):
        return (u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (
            v[..., 0] - o[..., 0]
        )

    P0, P1 = p0[:, None, :], p1[:, None, :]
    A, B = a[None], b[None]
    d1, d2 = cross(A, B, P0), cross(A, B, P1)
    d3, d4 = cross(P0, P1, A), cross(P0, P1, B)
    return np.any((d1 * d2 < 0) & (d3 * d4 < 0), axis=1)


def point_segment_distance(p, a, b):
    """``(n, s)`` distances from points to segments."""
    ab = b - a
    t = np.einsum("nsk,sk->ns", p[:, None, :] - a[None], ab) / np.einsum("sk,sk->s", ab, ab)
    t = np.clip(t, 0.0, 1.0)
    closest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(p[:, None, :] - closest, axis=2)


# -- registry and parameters --------------------------------------------------------------------
def test_registered_as_velocity_models():
    for name, cls in (("orca", OrcaModel), ("rvo2", Rvo2Model)):
        assert CROWD_MODELS.get(name) is cls
        assert "velocity_obstacle" in CROWD_MODELS.entry(name).tags
        assert cls.output == "velocity"
    model = CROWD_MODELS.build({"type": "rvo2", "neighbor_dist": 7.5, "time_horizon_obst": 3.0})
    assert isinstance(model, Rvo2Model) and model.neighbor_cutoff() == 7.5
    assert OrcaModel().neighbor_cutoff() == OrcaModel.Params().neighbor_dist
    with pytest.raises(ValidationError):
        OrcaModel.Params(time_horizon_obst=2.0)  # orca has no obstacles
    with pytest.raises(ValidationError):
        Rvo2Model.Params(time_horizon=0.0)
    with pytest.raises(ValidationError):
        OrcaModel.Params(bogus=1)


def test_preferred_velocity_matches_rvo2_examples():
    # RVO2's Circle example: goal vector, normalised when longer than 1 (unit speed).
    pos = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    goals = np.array([[3.0, 4.0], [0.3, 0.4], [1.0, 1.0]])
    pref = preferred_velocities(pos, goals, np.ones(3), 1.0)
    np.testing.assert_allclose(pref, [[0.6, 0.8], [0.3, 0.4], [0.0, 0.0]])
    # In general: full speed far away, (goal - p)/arrival_time on the last speed·T metres.
    pref = preferred_velocities(pos[:2], goals[:2], np.full(2, 1.5), 2.0)
    np.testing.assert_allclose(pref, [[0.9, 1.2], [0.15, 0.2]])


# -- reference runs against the C++ library -----------------------------------------------------
@pytest.mark.parametrize(("n", "radius"), [(12, 6.0), (16, 8.0)])
def test_orca_matches_rvo2_circle_crossing(n, radius):
    pos, goals = circle(n, radius)
    sim = pyrvo_sim(pos)
    # pyrvo stores float32: start from the same (rounded) positions.
    state = make_state(pyrvo_positions(sim), goals)
    model = OrcaModel(OrcaModel.Params(**REF, safety_margin=0.0, pref_perturbation=0.0))
    for _ in range(100):
        pyrvo_step(sim, goals)
        step(model, state, goals)
    err = np.abs(pyrvo_positions(sim) - state.positions).max()
    assert err <= README_ORCA_ERR, f"max position error after 100 steps: {err:.3g} m"
    # The agents actually interacted: they are far from where straight lines would take them.
    assert np.linalg.norm(state.positions - goals, axis=1).max() > 1.0


def test_rvo2_matches_rvo2_with_obstacle_lines():
    pos, goals = circle(16, 7.0)
    sim = pyrvo_sim(pos, polygons=SEGMENTS)
    assert sim.get_num_obstacle_vertices() == 14  # split by RVO2's obstacle tree
    state = make_state(pyrvo_positions(sim), goals)
    params = {**REF, "time_horizon_obst": REF_OBST, "safety_margin": 0.0, "pref_perturbation": 0.0}
    model = Rvo2Model(Rvo2Model.Params(**params))
    walls = walls_of(SEGMENTS)
    for _ in range(100):
        pyrvo_step(sim, goals)
        step(model, state, goals, walls=walls)
    err = np.abs(pyrvo_positions(sim) - state.positions).max()
    assert err <= README_RVO2_ERR, f"max position error after 100 steps: {err:.3g} m"


def ccw_area2(poly):
    """Twice the signed area of a ``(k, 2)`` polygon (positive: counter-clockwise)."""
    x, y = poly[:, 0], poly[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def room_with_two_boxes():
    """A walled 10 m room (grid walls) with two rotated boxes, one footprint clockwise."""
    occ = np.zeros((100, 100), dtype=bool)
    occ[:2] = occ[-2:] = occ[:, :2] = occ[:, -2:] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1, origin=(-5.0, -5.0))
    boxes = (
        Obstacle("a", "box", np.array([-0.9, 0.4, 0.3]), box(-0.6, -0.4, 0.6, 0.4)),
        Obstacle("b", "box", np.array([1.0, -0.7, -0.5]), box(-0.5, -0.5, 0.5, 0.5)[::-1]),
    )
    return StaticWorld.build(grid, boxes)


def test_rvo2_matches_rvo2_in_a_room_with_two_boxes():
    # RVO2 takes the boxes as closed polygons (addObstacle); the model gets them from the world
    # at reset, as the simulator runs it. The map's walls go to both as segments.
    world = room_with_two_boxes()
    pos, goals = circle(16, 3.8)
    sim = pyrvo.RVOSimulator(DT, *REF.values(), REF_OBST, RADIUS, VMAX)
    for p in pos:
        sim.add_agent((float(p[0]), float(p[1])))
    for a, b in zip(*grid_wall_segments(world.grid), strict=True):
        sim.add_obstacle([tuple(map(float, a)), tuple(map(float, b))])
    for ob in world.obstacles:
        poly = ob.polygon if ccw_area2(ob.polygon) > 0 else ob.polygon[::-1]
        sim.add_obstacle([tuple(map(float, q)) for q in poly])
    sim.process_obstacles()
    params = Rvo2Model.Params(
        **REF, time_horizon_obst=REF_OBST, safety_margin=0.0, pref_perturbation=0.0
    )
    model, segments_only = Rvo2Model(params), Rvo2Model(params)
    state = make_state(pyrvo_positions(sim), goals)
    model.reset(state, world, np.random.default_rng(0))
    other = make_state(pyrvo_positions(sim), goals)
    walls = world_segments(world)
    for _ in range(100):
        pyrvo_step(sim, goals)
        step(model, state, goals, walls=walls)
        step(segments_only, other, goals, walls=walls)  # no reset: the frame's segments alone
    err = np.abs(pyrvo_positions(sim) - state.positions).max()
    assert err <= README_RVO2_ERR, f"max position error after 100 steps: {err:.3g} m"
    # The boxes mattered: each edge as a separate segment takes the crowd elsewhere.
    assert np.abs(pyrvo_positions(sim) - other.positions).max() > 0.1


def test_world_polygons_are_rvo2_polygons():
    # Clockwise footprints turn counter-clockwise, a closing copy of the first vertex goes, an
    # L keeps its reflex corner non-convex: the same vertices, links and flags as pyrvo's.
    ell = np.array([[0.0, 0.0], [0.0, 2.0], [1.0, 2.0], [1.0, 1.0], [2.0, 1.0], [2.0, 0.0]])
    world = StaticWorld.build(
        OccupancyGrid.from_occupied(np.pad(np.zeros((30, 30), bool), 1, constant_values=True), 0.2),
        (
            Obstacle("l", "shelf", np.array([2.0, 2.5, 0.0]), np.vstack([ell, ell[:1]])),
            Obstacle("b", "box", np.array([4.5, 4.0, 0.7]), box(-0.4, -0.3, 0.4, 0.3)),
        ),
    )
    polys = world_polygons(world)
    ga, gb = grid_wall_segments(world.grid)
    assert len(polys) == len(ga) + 2
    for k, seg in enumerate(polys[: len(ga)]):
        np.testing.assert_array_equal(seg, [ga[k], gb[k]])
    np.testing.assert_array_equal(polys[-2], world.obstacles[0].polygon[:6][::-1])
    np.testing.assert_array_equal(polys[-1], world.obstacles[1].polygon)
    assert all(ccw_area2(p) > 0 for p in polys[-2:])
    sim = pyrvo_sim(np.zeros((0, 2)), polygons=polys)
    ob = Obstacles.from_polygons(polys, dtype=np.float32)
    m = sim.get_num_obstacle_vertices()
    ref = np.array([sim.get_obstacle_vertex(i).to_tuple() for i in range(m)])
    assert np.array_equal(ob.point, ref.astype(np.float32))
    assert np.array_equal(ob.next, [sim.get_next_obstacle_vertex(i) for i in range(m)])
    reflex = np.flatnonzero(~ob.convex)
    assert len(reflex) == 1
    np.testing.assert_allclose(ob.point[reflex[0]], [3.0, 3.5])  # the L's inner corner
    np.testing.assert_array_equal(counter_clockwise(np.array([[1.0, 1.0], [1.0, 1.0]])), [[1, 1]])


@pytest.mark.parametrize("layout", ["segments", "polygons"])
def test_float32_kernel_reproduces_rvo2(layout):
    """In float32 (the C++ library's float) the kernel reproduces RVO2 step for step.

    Bit for bit on x86-64; a small tolerance leaves room for compilers that fuse
    multiply-adds. 200 steps of 24 agents through obstacles, nearly every code path.
    """
    polys = [np.array(s) for s in SEGMENTS] if layout == "segments" else POLYGONS
    pos, goals = circle(24, 7.0)
    sim = pyrvo_sim(pos, polygons=polys)
    ob = Obstacles.from_polygons(polys, dtype=np.float32)
    n = len(pos)
    p = pyrvo_positions(sim).astype(np.float32)
    v = np.zeros((n, 2), dtype=np.float32)
    worst = 0.0
    for _ in range(200):
        pref = pyrvo_step(sim, goals).astype(np.float32)
        nb = find_neighbors(p.astype(np.float64), REF["neighbor_dist"])
        v = orca_velocities(
            p,
            v,
            np.full(n, RADIUS),
            np.full(n, VMAX),
            pref,
            np.ones(n, dtype=bool),
            (nb.indptr, nb.indices),
            **REF,
            time_horizon_obst=REF_OBST,
            dt=DT,
            obstacles=ob,
            dtype=np.float32,
        )
        assert v.dtype == np.float32
        p = p + v * np.float32(DT)
        worst = max(worst, float(np.abs(pyrvo_positions(sim) - p).max()))
    assert worst < 1e-5, f"float32 kernel drifted {worst:.3g} m from RVO2"


def test_obstacle_processing_matches_rvo2():
    """Same vertices, links and convexity as RVO2's addObstacle + processObstacles."""
    rng = np.random.default_rng(3)
    random_segments = [rng.uniform(-8.0, 8.0, (2, 2)) for _ in range(30)]
    for polys in (random_segments, [*POLYGONS, *[np.array(s) for s in SEGMENTS]]):
        sim = pyrvo_sim(np.zeros((0, 2)), polygons=polys)
        ob = Obstacles.from_polygons(polys, dtype=np.float32)
        m = sim.get_num_obstacle_vertices()
        assert len(ob) == m > sum(len(p) for p in polys)  # edges were split
        ref = np.array([sim.get_obstacle_vertex(i).to_tuple() for i in range(m)])
        assert np.array_equal(ob.point, ref.astype(np.float32))
        assert np.array_equal(ob.next, [sim.get_next_obstacle_vertex(i) for i in range(m)])
        assert np.array_equal(ob.prev, [sim.get_prev_obstacle_vertex(i) for i in range(m)])
    # Convexity: the L's reflex corner is its only non-convex vertex (splits are convex).
    ob = Obstacles.from_polygons(POLYGONS[3:])
    assert ob.convex[:6].tolist() == [True, True, True, False, True, True]
    assert ob.convex[6:].all()


# -- behaviour ----------------------------------------------------------------------------------
def pairwise_gap(state):
    d = np.linalg.norm(state.positions[:, None] - state.positions[None], axis=2)
    gap = d - (state.radii[:, None] + state.radii[None])
    np.fill_diagonal(gap, np.inf)
    return gap.min()


def random_room(n, size, seed):
    """``n`` non-overlapping agents in a square room, each heading to another's start."""
    rng = np.random.default_rng(seed)
    pts = []
    while len(pts) < n:
        p = rng.uniform(0.5, size - 0.5, 2)
        if all(np.hypot(*(p - q)) > 2 * RADIUS + 0.1 for q in pts):
            pts.append(p)
    pos = np.array(pts)
    return pos, pos[rng.permutation(n)]


@pytest.mark.parametrize("name", ["orca", "rvo2"])
def test_dense_crossing_no_overlap_and_speed_cap(name):
    # 40 people in an 8 x 8 m room (0.6 per m²), all crossing to someone else's place.
    pos, goals = random_room(40, 8.0, seed=0)
    vmax = np.random.default_rng(2).uniform(0.8, 1.4, len(pos))
    state = make_state(pos, goals, vmax=vmax)
    walls = walls_of([((0, 0), (8, 0)), ((8, 0), (8, 8)), ((8, 8), (0, 8)), ((0, 8), (0, 0))])
    model = CROWD_MODELS.build(name)
    rng = np.random.default_rng(1)
    worst = np.inf
    for _ in range(400):
        v = step(model, state, goals, walls=walls, rng=rng)
        assert np.all(np.hypot(v[:, 0], v[:, 1]) <= vmax + 1e-9)
        worst = min(worst, pairwise_gap(state))
    assert worst > -1e-3, f"agents overlap by {-worst:.3g} m"
    # ...and the crowd got through (ORCA has no planner: one may stay boxed in a corner).
    assert np.mean(np.linalg.norm(state.positions - goals, axis=1) < 0.5) >= 0.9


def test_rvo2_itself_overlaps_slightly_without_safety_margin():
    """RVO2 lets agents overlap when its linear program is infeasible (dense converging
    crowds); without a margin we do the same, which is why the default adds 5 cm.
    """
    pos, goals = circle(16, 4.0)
    vmax = np.linspace(0.8, 1.4, 16)
    model = OrcaModel(OrcaModel.Params(safety_margin=0.0, pref_perturbation=0.0))
    state = make_state(pos, goals, vmax=vmax)
    worst = np.inf
    for _ in range(150):
        step(model, state, goals)
        worst = min(worst, pairwise_gap(state))
    assert -0.03 < worst < -1e-3
    default = make_state(pos, goals, vmax=vmax)
    worst = np.inf
    for _ in range(150):
        step(OrcaModel(), default, goals)
        worst = min(worst, pairwise_gap(default))
    assert worst > -1e-3


def test_max_speed_follows_vmax_factor():
    pos = np.column_stack([np.arange(6) * 20.0, np.zeros(6)])  # far apart: no interaction
    goals = pos + np.array([0.0, 50.0])
    state = make_state(pos, goals, vmax=1.2)
    state.vmax_factor = np.array([1.0, 0.5, 0.0, 1.5, 1.0, 0.25])
    v = step(OrcaModel(OrcaModel.Params(pref_perturbation=0.0)), state, goals)
    speed = np.hypot(v[:, 0], v[:, 1])
    assert np.all(speed <= 1.2 * state.vmax_factor + 1e-9)
    np.testing.assert_allclose(speed[[0, 1, 3]], [1.2, 0.6, 1.8], rtol=1e-6)


def test_inactive_agents_get_zero_and_are_avoided():
    # Agent 0 walks straight at a standing (inactive) agent 1; agent 2 is inactive elsewhere.
    pos = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 5.0]])
    goals = np.array([[6.0, 0.0], [-3.0, 0.0], [5.0, 5.0]])
    state = make_state(pos, goals)
    active = np.array([True, False, False])
    model = OrcaModel()
    gap = np.inf
    for _ in range(120):
        v = step(model, state, goals, active=active)
        assert np.all(v[~active] == 0.0)
        gap = min(gap, pairwise_gap(state))
    np.testing.assert_array_equal(state.positions[1:], pos[1:])
    assert gap > -1e-3, f"walked into a standing agent: overlap {-gap:.3g} m"
    assert np.linalg.norm(state.positions[0] - goals[0]) < 0.5  # and got past it


@pytest.mark.parametrize("name", ["orca", "rvo2"])
def test_deterministic_and_independent_of_neighbour_order(name):
    pos, goals = circle(20, 4.0, jitter=0.2, seed=4)
    walls = walls_of(SEGMENTS)

    def run(shuffle):
        state = make_state(pos, goals)
        model = CROWD_MODELS.build(name)
        rng = np.random.default_rng(9)
        out = []
        for _ in range(60):
            nb = find_neighbors(state.positions, model.neighbor_cutoff())
            if shuffle:  # the cell list's order is arbitrary: the result must not depend on it
                idx = nb.indices.copy()
                for i in range(len(state)):
                    sl = slice(nb.indptr[i], nb.indptr[i + 1])
                    idx[sl] = idx[sl][::-1]
                nb = type(nb)(nb.indptr, idx, nb.cutoff)
            frame = CrowdFrame(
                state, goals, np.ones(len(state), bool), RobotView.empty(), *walls, nb, DT, rng
            )
            v = model.compute(frame).velocities
            state.velocities, state.positions = v, state.positions + v * DT
            out.append(state.positions.copy())
        return np.array(out)

    a, b, c = run(False), run(False), run(True)
    assert np.array_equal(a, b)
    assert np.array_equal(a, c)


def test_rvo2_never_passes_through_obstacle_lines():
    # A long wall between every agent and its goal, a post, a diagonal bar and a box.
    segs = [((-4.0, 0.0), (4.0, 0.0)), ((-1.0, 2.8), (-1.0, 3.8)), ((1.5, -3.0), (2.5, -2.0))]
    corners = box(-3.0, -3.8, -2.0, -2.8)
    segs += [(tuple(corners[k]), tuple(corners[(k + 1) % 4])) for k in range(4)]
    wa, wb = walls_of(segs)
    xs = np.arange(-3.2, 3.3, 0.8)
    pos = np.array([(x, y) for y in (-1.7, -0.9, 0.9, 1.7) for x in xs])
    goals = np.column_stack([np.sign(pos[:, 0] + 1e-9) * 6.0, -np.sign(pos[:, 1]) * 4.5])
    state = make_state(pos, goals)
    model = Rvo2Model()
    gap = np.inf
    for _ in range(300):
        p0 = state.positions.copy()
        step(model, state, goals, walls=(wa, wb))
        assert not segment_crossings(p0, state.positions, wa, wb).any(), "crossed a wall"
        gap = min(gap, float((point_segment_distance(state.positions, wa, wb) - RADIUS).min()))
    assert gap > -1e-3, f"an agent came {-gap:.3g} m inside a wall's clearance"
    # They pressed against the long wall and went around its ends.
    assert np.mean(np.sign(state.positions[:, 1]) != np.sign(pos[:, 1])) > 0.5


def test_orca_ignores_walls_rvo2_does_not():
    pos = np.array([[0.0, -1.0]])
    goals = np.array([[0.0, 3.0]])
    walls = walls_of([((-3.0, 0.0), (3.0, 0.0))])
    s_orca, s_rvo2 = make_state(pos, goals), make_state(pos, goals)
    for _ in range(30):
        step(OrcaModel(), s_orca, goals, walls=walls)
        step(Rvo2Model(), s_rvo2, goals, walls=walls)
    assert s_orca.positions[0, 1] > 0.5  # walked through (the simulator's wall guard stops it)
    assert s_rvo2.positions[0, 1] < -RADIUS + 1e-3


@pytest.mark.parametrize("avoid", [True, False])
def test_robots_are_avoided_as_non_reciprocating_obstacles(avoid):
    # A robot drives at constant velocity straight at a pedestrian walking toward it.
    pos = np.array([[0.0, 0.0]])
    goals = np.array([[8.0, 0.0]])
    state = make_state(pos, goals)
    model = OrcaModel(OrcaModel.Params(avoid_robots=avoid))
    r_pos, r_vel, r_rad = np.array([[6.0, 0.0]]), np.array([[-0.8, 0.0]]), np.array([0.4])
    gap = np.inf
    for _ in range(100):
        robots = RobotView(r_pos.copy(), np.array([np.pi]), r_vel, r_rad)
        step(model, state, goals, robots=robots)
        r_pos = r_pos + r_vel * DT  # the robot does not react
        gap = min(gap, float(np.linalg.norm(state.positions[0] - r_pos[0]) - RADIUS - r_rad[0]))
    if avoid:
        assert gap > -1e-3, f"pedestrian hit the robot: overlap {-gap:.3g} m"
    else:
        assert gap < 0.0


def test_coincident_agents_separate_without_nan():
    state = make_state(np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([[1.0, 1.0], [1.0, 1.0]]))
    v = step(OrcaModel(OrcaModel.Params(pref_perturbation=0.0)), state, state.positions.copy())
    assert np.all(np.isfinite(v))
    assert v[0, 0] < 0 < v[1, 0]  # pushed apart along x, lower index to the left


def test_obstacles_from_world_segments_drop_degenerate():
    a = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]])
    b = np.array([[1.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    ob = Obstacles.from_segments(a, b)
    assert len(ob) == 4  # two real segments, two vertices each
    np.testing.assert_array_equal(ob.next, [1, 0, 3, 2])
    assert ob.convex.all()
    assert len(Obstacles.from_segments(np.zeros((0, 2)), np.zeros((0, 2)))) == 0

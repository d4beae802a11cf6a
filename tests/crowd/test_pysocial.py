"""``pysocial`` against references: PyPI ``pysocialforce`` 1.1.2 and the plain formulations.

Every force term is checked against ``pysocialforce``, the compiled kernels against their plain
NumPy / Python formulations (to the bit); the behaviour tests are in
``test_pysocial_behaviour.py``.

The reference tests need the package (``pip install pysocialforce==1.1.2``, in the ``test``
extra) and skip without it. PySocialForce sets the root logger to DEBUG and opens ``file.log``
in the working directory when imported, so the ``psf`` fixture imports it in a scratch
directory and undoes the logging changes.
"""

from __future__ import annotations

import logging
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from arena.crowd.base import RobotView
from arena.crowd.models.pysocial.model import TERMS, PySocialModel, sample_segments
from arena.crowd.state import CrowdState
from arena.crowd.walls import world_segments
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle, StaticWorld
from tests.crowd.pysocial_kit import EXACT, make_frame, make_state, ours, random_scene

# PySocialForce's term order in Simulator.forces (enable_group): desired, social, obstacle,
# group coherence (Alt), group repulsion, group gaze (Alt).
REF_TERMS = ("desired", "social", "obstacle", "group_coherence", "group_repulsion", "group_gaze")
# README: "forces equal to 2e-15" of the largest reference force (measured: at most 1.1e-15,
# 2026-11-27, on x86-64 with AVX-512, where numpy's SIMD exp/arctan2 differ most from libm).
RTOL = 2e-15


@pytest.fixture(scope="module")
def psf(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The ``pysocialforce`` package, imported without its side effects on logging and cwd."""
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    cwd = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("pysocialforce"))
    try:
        return pytest.importorskip("pysocialforce")
    finally:
        os.chdir(cwd)
        for h in root.handlers[:]:
            if h not in handlers:
                root.removeHandler(h)
                h.close()
        root.setLevel(level)



def reference(
    psf: Any, world: StaticWorld | None, state: CrowdState, dest: np.ndarray, config: Any = None
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``pysocialforce.Simulator.compute_forces()`` and its terms for the same scene.

    Conventions: state rows ``(px, py, vx, vy, gx, gy)`` with the absolute goal; obstacles as
    ``(x0, x1, y0, y1)`` lines, here the world's segments; groups as index lists. Its desired
    speed is ``max_speed_multiplier (1.3) × |v|`` of the *first* state it sees, so the simulator
    is built with velocities of speed ``vmax·vmax_factor / 1.3`` and then given the real state.
    """
    lines = None
    if world is not None:
        a, b = world_segments(world)
        lines = [(a[k, 0], b[k, 0], a[k, 1], b[k, 1]) for k in range(len(a))]
    n = len(state)
    speed = state.vmax * state.vmax_factor / 1.3
    heading = np.linspace(0.0, 2 * np.pi, n, endpoint=False)  # any direction will do
    first = np.c_[state.positions, speed * np.cos(heading), speed * np.sin(heading), dest]
    ids = np.unique(state.group[state.group >= 0])
    groups = [np.flatnonzero(state.group == g).tolist() for g in ids]
    sim = psf.Simulator(first, groups=groups, obstacles=lines, config_file=config)
    sim.peds.update(np.c_[state.positions, state.velocities, dest], groups)
    np.testing.assert_allclose(sim.peds.max_speeds, state.vmax * state.vmax_factor, rtol=1e-14)
    terms = dict(zip(REF_TERMS, (f.get_force() for f in sim.forces), strict=True))
    return sim.compute_forces(), terms


def rel_error(a: np.ndarray, ref: np.ndarray) -> float:
    """Largest deviation relative to the largest reference value (0 where both vanish)."""
    scale = float(np.max(np.abs(ref), initial=0.0))
    err = float(np.max(np.abs(a - ref), initial=0.0))
    return err / scale if scale > 0 else err


def assert_matches(out: Any, total: np.ndarray, terms: dict[str, np.ndarray]) -> None:
    for name, ref in terms.items():
        err = rel_error(out.forces[name], ref)
        assert err <= RTOL, f"{name}: {err:.3g} of the largest force"
    err = rel_error(out.accelerations, total)
    assert err <= RTOL, f"total: {err:.3g} of the largest force"


# -- reference ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("seed", "n"), [(0, 10), (1, 14), (2, 18), (3, 22), (4, 26), (5, 30), (6, 16), (11, 21)]
)
def test_every_term_matches_pysocialforce(psf: Any, seed: int, n: int) -> None:
    world, state, dest = random_scene(seed, n)
    assert (state.group >= 0).sum() >= 2, "the scene must have groups"
    total, terms = reference(psf, world, state, dest)
    out = ours(world, make_frame(state, dest), **EXACT)
    assert_matches(out, total, terms)
    for name in REF_TERMS:  # every term is exercised, not trivially zero
        if name != "group_repulsion":
            assert np.abs(terms[name]).max() > 0, name


def test_matches_pysocialforce_when_members_crowd_and_walls_are_close(psf: Any) -> None:
    # Tight groups (repulsion active) pressed against walls (obstacle force strong).
    rng = np.random.default_rng(11)
    base = rng.uniform([0.5, 0.5], [5.5, 3.5], (6, 2))
    pos = np.concatenate([base, base + rng.uniform(-0.25, 0.25, (6, 2))])
    groups = np.r_[np.arange(6), np.arange(6)]
    state = make_state(pos, rng.normal(0, 0.5, (12, 2)), vmax=1.3, groups=groups)
    dest = rng.uniform([1, 1], [5, 3], (12, 2))
    world = StaticWorld.build(OccupancyGrid.empty(6.0, 4.0, 0.05))
    total, terms = reference(psf, world, state, dest)
    assert np.abs(terms["group_repulsion"]).max() > 0
    assert_matches(ours(world, make_frame(state, dest), **EXACT), total, terms)


def test_matches_a_custom_pysocialforce_config(psf: Any, tmp_path: Path) -> None:
    # Every parameter changed; the *_alt sections and the top-level scene keys are where
    # PySocialForce's simulator really reads them.
    cfg = tmp_path / "custom.toml"
    cfg.write_text(
        "resolution = 5.0\nagent_radius = 0.3\n"
        "[scene]\nenable_group = true\n"
        "[desired_force]\nfactor = 2.5\nrelaxation_time = 0.8\ngoal_threshold = 0.3\n"
        "[social_force]\nfactor = 10.1\nlambda_importance = 1.5\ngamma = 0.4\nn = 2.5\n"
        "n_prime = 3.5\n"
        "[obstacle_force]\nfactor = 7.0\nsigma = 0.3\nthreshold = 2.0\n"
        "[group_coherence_force_alt]\nfactor = 3.0\n"
        "[group_repulsive_force]\nfactor = 1.5\nthreshold = 0.7\n"
        "[group_gaze_force_alt]\nfactor = 4.0\n"
    )
    params = {
        "desired_factor": 2.5,
        "relaxation_time": 0.8,
        "goal_threshold": 0.3,
        "social_factor": 10.1,
        "lambda_importance": 1.5,
        "gamma": 0.4,
        "n": 2.5,
        "n_prime": 3.5,
        "obstacle_factor": 7.0,
        "obstacle_sigma": 0.3,
        "obstacle_threshold": 2.0,
        "agent_radius": 0.3,
        "resolution": 5.0,
        "group_coherence_factor": 3.0,
        "group_repulsion_factor": 1.5,
        "group_repulsion_threshold": 0.7,
        "group_gaze_factor": 4.0,
    }
    world, state, dest = random_scene(7, 20, min_side=0.5)  # lines ≥ 2/resolution
    total, terms = reference(psf, world, state, dest, config=str(cfg))
    assert_matches(ours(world, make_frame(state, dest), **EXACT, **params), total, terms)


def test_defaults_are_the_factors_pysocialforce_applies(psf: Any) -> None:
    sim = psf.Simulator(np.array([[0.0, 0.0, 1.0, 0.0, 5.0, 0.0]]))
    p = PySocialModel.Params()
    factors = {type(f).__name__: f.factor for f in sim.forces}
    assert factors == {
        "DesiredForce": p.desired_factor,
        "SocialForce": p.social_factor,
        "ObstacleForce": p.obstacle_factor,
        # The toml's group_coherence_force (3.0) and group_gaze_force (4.0) sections are not
        # read: these classes look for *_alt sections and fall back to 1.0.
        "GroupCoherenceForceAlt": p.group_coherence_factor,
        "GroupRepulsiveForce": p.group_repulsion_factor,
        "GroupGazeForceAlt": p.group_gaze_factor,
    }
    assert sim.peds.agent_radius == p.agent_radius
    assert sim.env.resolution == p.resolution
    assert sim.peds.max_speed_multiplier == 1.3
    # Read from the config's top level, where default.toml has no such key: 0.4, not 1.0.
    assert sim.peds.step_width == 0.4


def test_obstacle_sampling_matches_pysocialforce(psf: Any) -> None:
    rng = np.random.default_rng(3)
    a = rng.uniform(0, 10, (20, 2))
    b = a + rng.uniform(-4, 4, (20, 2))
    # Round lengths at every angle: int() truncation of a last-bit length difference would
    # change the point count (6 m rotated is 59.99999999999999 samples for PySocialForce).
    angle = rng.uniform(-np.pi, np.pi, 60)
    length = np.repeat([6.0, 0.3, 1.0], 20)
    a = np.r_[a, rng.uniform(0, 5, (60, 2))]
    b = np.r_[b, a[20:] + length[:, None] * np.c_[np.cos(angle), np.sin(angle)]]
    lines = [(a[k, 0], b[k, 0], a[k, 1], b[k, 1]) for k in range(len(a))]
    env = psf.scene.EnvState(lines, 10)
    np.testing.assert_allclose(sample_segments(a, b, 10.0), np.vstack(env.obstacles), atol=1e-12)
    # Deliberate difference: short lines keep their two end points (PySocialForce: 1 or 0).
    short = sample_segments(
        np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([[0.15, 0.0], [1.0, 1.0]]), 10.0
    )
    np.testing.assert_array_equal(short, [[0.0, 0.0], [0.15, 0.0]])


def test_unwrapped_theta_quirk_matches_and_wrap_theta_is_rotation_invariant(psf: Any) -> None:
    # e = unit(r_i − r_j) just above the negative x-axis, t just below it: PySocialForce's raw
    # arctan2 difference is θ ≈ 0.2 − 2π and agent i's force almost vanishes.
    pos = np.array([[0.0, 0.0], [1.0, -0.05]])
    vel = np.array([[0.0, 0.0], [0.0, -0.1]])
    dest = np.array([[-5.0, 0.0], [5.0, 0.0]])
    state = make_state(pos, vel)
    total, terms = reference(psf, None, state, dest)
    raw = ours(None, make_frame(state, dest), **EXACT)
    assert_matches(raw, total, terms)
    wrapped = ours(None, make_frame(state, dest), **EXACT, wrap_theta=True)
    assert np.linalg.norm(raw.forces["social"][0]) < 1e-6
    assert np.linalg.norm(wrapped.forces["social"][0]) > 0.1
    # Rotated by 90°, nothing straddles the cut: upstream's θ is the wrapped one.
    rot = np.array([[0.0, -1.0], [1.0, 0.0]])
    turned = make_state(pos @ rot.T, vel @ rot.T)
    turned_out = ours(None, make_frame(turned, dest @ rot.T), **EXACT)
    np.testing.assert_allclose(
        turned_out.forces["social"], wrapped.forces["social"] @ rot.T, atol=1e-12
    )



# -- the compiled kernels against their plain NumPy / Python formulations (to the bit) ----------
def test_desired_kernel_is_desired_force_to_the_bit() -> None:
    from arena.crowd.models.pysocial.kernels import _desired
    from arena.crowd.models.pysocial.model import desired_force

    rng = np.random.default_rng(11)
    n = 200
    pos = rng.uniform(0, 10, (n, 2))
    vel = rng.normal(0, 1, (n, 2))
    dest = rng.uniform(0, 10, (n, 2))
    dest[:20] = pos[:20] + rng.uniform(-0.1, 0.1, (20, 2))  # inside the goal threshold: brake
    dest[20:25] = pos[20:25]  # on the destination
    vmax, factor = rng.uniform(0.3, 1.5, n), rng.choice([0.0, 0.5, 1.0], n)
    out = np.empty((n, 2))
    for tau, threshold in ((0.5, 0.2), (0.3, 0.0)):
        _desired(pos, vel, dest, vmax, factor, tau, threshold, out)
        want = desired_force(pos, vel, dest, vmax * factor, tau, threshold)
        assert out.tobytes() == want.tobytes()


def plain_obstacle_sum(
    pos: np.ndarray, radii: np.ndarray, points: np.ndarray, threshold: float, sigma: float
) -> np.ndarray:
    """PySocialForce's obstacle sum per agent, point by point in ``points``' order (Python)."""
    out = np.zeros((len(pos), 2))
    for i, (x, y) in enumerate(pos.tolist()):
        r = float(radii[i])
        thr = threshold + r
        far2 = (thr + r) * (thr + r) * (1.0 + 1e-9)
        fx = fy = 0.0
        for px, py in points.tolist():
            dx, dy = x - px, y - py
            d2 = dx * dx + dy * dy
            dist = math.sqrt(d2)
            if d2 < far2 and dist - r < thr and dist > 0.0:
                w = math.exp(-(dist - r) / sigma)
                fx += dx / dist * w
                fy += dy / dist * w
        out[i] = fx, fy
    return out


@pytest.mark.parametrize("agent_radius", [0.35, None])
def test_obstacle_term_is_the_plain_sum_in_cell_order_to_the_bit(
    agent_radius: float | None,
) -> None:
    """Pruned cells and blocks, runs and the vectorised pass change no bit of the sum."""
    world, state, dest = random_scene(7, 30)
    state.radii = np.random.default_rng(7).uniform(0.2, 0.5, 30)
    state.positions[0] = world_segments(world)[0][3]  # on a wall point: distance 0, skipped
    model = PySocialModel(PySocialModel.Params(agent_radius=agent_radius))
    model.reset(state, world, np.random.default_rng(0))
    out = model.compute(make_frame(state, dest, search=10.0))
    cells = model._cells
    radii = state.radii if agent_radius is None else np.full(30, agent_radius)
    p = model.params
    want = plain_obstacle_sum(
        state.positions, radii, cells.points[cells.order], p.obstacle_threshold, p.obstacle_sigma
    )
    assert out.forces["obstacle"].tobytes() == (want * p.obstacle_factor).tobytes()
    assert np.abs(want).max() > 0


def test_accelerations_are_the_terms_summed_in_order_to_the_bit() -> None:
    world, state, dest = random_scene(8, 20)
    active = np.ones(20, dtype=bool)
    active[[2, 7]] = False
    robots = RobotView(np.array([[6.0, 5.0]]), np.zeros(1), np.array([[0.5, 0.0]]), np.ones(1))
    frame = make_frame(state, dest, active=active, robots=robots, search=10.0)
    for scale in (1.0, 0.3):
        out = ours(world, frame, force_scale=scale)
        total = np.zeros((20, 2))
        for name in TERMS:  # what NumPy does: 0 + desired + social + ...
            total += out.forces[name]
        assert out.accelerations.tobytes() == total.tobytes()
        assert np.all(out.accelerations[~active] == 0.0)
        assert all(np.abs(out.forces[k]).max() > 0 for k in ("social", "obstacle", "robot"))


def test_groups_edited_in_place_are_seen() -> None:
    world, state, dest = random_scene(9, 12)
    model = PySocialModel()
    model.reset(state, world, np.random.default_rng(0))
    frame = make_frame(state, dest, search=10.0)
    model.compute(frame)
    state.group[:] = -1
    state.group[[0, 1, 2]] = 5  # same array, new groups
    again = model.compute(frame)
    fresh = ours(world, frame)
    for name in TERMS:
        assert again.forces[name].tobytes() == fresh.forces[name].tobytes(), name


def test_nan_max_kernel_is_numpys_max() -> None:
    """The obstacle reach's maximum radius, taken in the kernel, is ``ndarray.max``'s."""
    from arena.crowd.models.pysocial.kernels import _nan_max

    rng = np.random.default_rng(3)
    cases = [rng.uniform(0.1, 0.6, n) for n in (1, 2, 7, 40)]
    cases += [np.array([0.3, np.nan, 0.5]), np.array([np.nan]), np.array([0.2, 0.2, np.inf])]
    for x in cases:
        assert np.array_equal(_nan_max(x), x.max(), equal_nan=True)


def test_reset_points_are_the_episode_segments_sampled() -> None:
    """Map walls sampled once per map plus this episode's obstacle edges == sampling them all."""
    from arena.crowd.simulator import episode_segments

    occ = np.zeros((60, 80), dtype=bool)
    occ[20:40, 30:33] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    other = OccupancyGrid.from_occupied(np.roll(occ, 7, axis=1), 0.1)
    box = np.array([[-0.4, -0.3], [0.4, -0.3], [0.4, 0.3], [-0.4, 0.3]])
    state = CrowdState.from_spawn(AgentSpawn.empty())
    model = PySocialModel()
    for g, obstacles in [
        (grid, ()),
        (grid, (Obstacle("a", "cuboid", np.array([2.0, 2.0, 0.4]), box),)),
        (grid, (Obstacle("b", "cuboid", np.array([6.0, 4.0, -1.0]), box),)),
        (other, (Obstacle("b", "cuboid", np.array([6.0, 4.0, -1.0]), box),)),
    ]:
        world = StaticWorld.build(g, obstacles)
        model.reset(state, world, np.random.default_rng(0))
        want = sample_segments(*episode_segments(world), model.params.resolution)
        assert model.obstacle_points.tobytes() == want.tobytes()
        ref = PySocialModel()
        ref.set_obstacles(*episode_segments(world))
        np.testing.assert_array_equal(model._cells.order, ref._cells.order)
        np.testing.assert_array_equal(model._obstacles.xy, ref._obstacles.xy)

"""Deep Social Force: shipped MLP potential, closed-form gradients, forces, torch-free runtime."""

from __future__ import annotations

import ast
import inspect
import math
import subprocess
import sys

import numpy as np
import pytest

from arena.crowd.base import CROWD_MODELS, CrowdFrame, RobotView
from arena.crowd.models import deep_social_force as dsf_module
from arena.crowd.models.deep_social_force import DeepSocialForce, _dvdb
from arena.crowd.models.deep_social_force_params import WEIGHTS, MLPPotential
from arena.crowd.neighbors import find_neighbors
from arena.crowd.state import CrowdState
from arena.scene.episode import AgentSpawn
from arena.testing.conformance import check_crowd_model

V0, SIGMA, DT_B = 2.1, 0.3, 0.4  # the generator potential the weights were trained on
NO_WALLS = (np.zeros((0, 2)), np.zeros((0, 2)))


def analytic_force(b):
    """−dV/db of V = 2.1·exp(−b/0.3) (m/s²)."""
    return V0 / SIGMA * np.exp(-np.asarray(b) / SIGMA)


def semi_minor_axis(r_ab, speed_b, e_b):
    """Helbing–Molnár's b for r_ab = x_a − x_b (plain numpy, for finite differences)."""
    s = DT_B * speed_b
    u = r_ab - s * np.asarray(e_b)
    return 0.5 * math.sqrt((np.linalg.norm(r_ab) + np.linalg.norm(u)) ** 2 - s * s)


def make_state(positions, *, vmax=1.0, velocities=None) -> CrowdState:
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    n = len(p)
    spawn = AgentSpawn(
        positions=p,
        radii=np.full(n, 0.3),
        vmax=np.full(n, vmax),
        waypoints=p[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
    )
    s = CrowdState.from_spawn(spawn)
    if velocities is not None:
        s.velocities = np.asarray(velocities, dtype=float).reshape(n, 2)
    return s


def make_frame(model, state, *, dt=0.001, dest, active=None, robots=None, walls=NO_WALLS):
    n = len(state)
    return CrowdFrame(
        state=state,
        destinations=np.asarray(dest, dtype=float),
        active=np.ones(n, dtype=bool) if active is None else np.asarray(active, dtype=bool),
        robots=robots or RobotView.empty(),
        walls_a=walls[0],
        walls_b=walls[1],
        neighbors=find_neighbors(state.positions, model.neighbor_cutoff()),
        dt=dt,
        rng=np.random.default_rng(0),
    )


@pytest.fixture(scope="module")
def mlp() -> MLPPotential:
    return MLPPotential.load()


# -- the shipped weights ----------------------------------------------------------------------


def test_shipped_weights_are_small_and_documented(mlp):
    assert WEIGHTS.stat().st_size < 8_000
    meta = mlp.metadata
    for key in ("architecture", "command", "train_steps", "wall_time_s", "final_loss_m", "data"):
        assert key in meta, key
    assert "synthetic" in meta["data"] and "No real pedestrian data" in meta["data"]
    assert "train_deep_social_force.py" in meta["command"]
    assert meta["final_loss_m"] < 1e-3  # mean position error after 0.4 s, m


def test_mlp_potential_monotonically_decreasing(mlp):
    b = np.linspace(0.1, 3.0, 1000)
    assert np.all(mlp.dvdb(b) < 0.0)
    assert np.all(np.diff(mlp.value(b)) < 0.0)


@pytest.mark.parametrize("b", [0.3, 0.5, 0.8, 1.0, 1.5, 2.0])
def test_mlp_force_matches_generator_potential(mlp, b):
    # Tolerance: 10 % of the generator's force plus 0.01 m/s² (the training data covers
    # 0.3 ≤ b ≤ 2 m densely; the force there ranges 2.6 … 0.009 m/s²).
    expected = analytic_force(b)
    assert -mlp.dvdb(np.array(b)) == pytest.approx(expected, abs=0.1 * expected + 0.01)


def test_numpy_gradient_equals_finite_differences(mlp):
    b = np.linspace(0.05, 4.0, 200)
    eps = 1e-6
    fd = (mlp.value(b + eps) - mlp.value(b - eps)) / (2 * eps)
    np.testing.assert_allclose(mlp.dvdb(b), fd, rtol=1e-6, atol=1e-9)


def test_numba_gradient_equals_numpy(mlp):
    for b in (0.0, 0.2, 0.7, 1.9, 5.0, 150.0):
        got = _dvdb(b, 0, mlp.w1, mlp.b1, mlp.w2, mlp.b2, 0.0, 1.0)
        assert got == pytest.approx(float(mlp.dvdb(np.array(b))), rel=1e-12, abs=1e-15)


# -- forces -----------------------------------------------------------------------------------


def _pair_case():
    """a at the origin heading +x; b ahead-left walking toward −x at 1.2 m/s."""
    pos = np.array([[0.0, 0.0], [1.1, 0.4]])
    vel = np.array([[0.8, 0.0], [-1.2, 0.0]])
    dest = np.array([[10.0, 0.0], [-10.0, 0.4]])
    return pos, vel, dest


@pytest.mark.parametrize("potential", ["mlp", "analytic"])
def test_pair_force_is_minus_gradient_of_v_of_b(mlp, potential):
    model = DeepSocialForce(DeepSocialForce.Params(potential=potential))
    value = mlp.value if potential == "mlp" else (lambda b: V0 * np.exp(-b / SIGMA))
    pos, vel, dest = _pair_case()
    s = make_state(pos, velocities=vel)
    out = model.compute(make_frame(model, s, dest=dest))
    # −∇_{x_a} V(b(x_a − x_b)) by central differences, b's speed and direction held fixed.
    e_b = (dest[1] - pos[1]) / np.linalg.norm(dest[1] - pos[1])
    eps = 1e-6
    grad = np.zeros(2)
    for k in range(2):
        d = np.zeros(2)
        d[k] = eps
        hi = value(semi_minor_axis(pos[0] + d - pos[1], 1.2, e_b))
        lo = value(semi_minor_axis(pos[0] - d - pos[1], 1.2, e_b))
        grad[k] = (hi - lo) / (2 * eps)
    np.testing.assert_allclose(out.forces["social"][0], -grad, rtol=1e-6, atol=1e-9)


def test_field_of_view_halves_force_from_behind():
    model = DeepSocialForce()
    pos, _, _ = _pair_case()
    s = make_state(pos, velocities=np.zeros((2, 2)))
    ahead = model.compute(make_frame(model, s, dest=[[10.0, 0.0], [1.1, 0.4]]))
    behind = model.compute(make_frame(model, s, dest=[[-10.0, 0.0], [1.1, 0.4]]))
    np.testing.assert_allclose(behind.forces["social"][0], 0.5 * ahead.forces["social"][0])


def test_wall_potential_force():
    model = DeepSocialForce()
    d = 0.4
    s = make_state([[1.0, d]])
    walls = (np.array([[0.0, 0.0]]), np.array([[2.0, 0.0]]))
    out = model.compute(make_frame(model, s, dest=[[1.0, d]], walls=walls))
    assert out.forces["obstacle"][0] == pytest.approx([0.0, 10.0 / 0.2 * math.exp(-d / 0.2)])


def test_robot_repels_like_a_pedestrian():
    model = DeepSocialForce()
    pos, vel, dest = _pair_case()
    s = make_state(pos[:1], velocities=vel[:1])
    robots = RobotView(pos[1:], np.array([math.pi]), vel[1:], np.array([0.3]))
    out = model.compute(make_frame(model, s, dest=dest[:1], robots=robots))
    both = make_state(pos, velocities=vel)
    ref = model.compute(make_frame(model, both, dest=dest))
    np.testing.assert_allclose(out.forces["robot"][0], ref.forces["social"][0], rtol=1e-12)
    off = DeepSocialForce(DeepSocialForce.Params(robots_as_pedestrians=False))
    assert np.all(
        off.compute(make_frame(off, s, dest=dest[:1], robots=robots)).forces["robot"] == 0
    )


def test_desired_term():
    model = DeepSocialForce()
    s = make_state([[0.0, 0.0]], vmax=1.3, velocities=[[0.2, 0.1]])
    out = model.compute(make_frame(model, s, dest=[[0.0, 5.0]]))
    assert out.forces["desired"][0] == pytest.approx([-0.2 / 0.5, (1.3 - 0.1) / 0.5])


def test_substeps_land_where_fine_integration_goes():
    """With max_substep = 0.02 s, two 0.1 s steps put agents where ten 0.02 s steps do."""
    pos, vel, dest = _pair_case()
    params = DeepSocialForce.Params(max_substep=0.02)
    coarse_model, fine_model = DeepSocialForce(params), DeepSocialForce(params)
    coarse, fine = make_state(pos, vmax=1.2, velocities=vel), make_state(pos, vmax=1.2)
    fine.velocities = coarse.velocities.copy()
    walls = (np.array([[-2.0, -0.6]]), np.array([[4.0, -0.6]]))

    def step(model, state, dt):
        out = model.compute(make_frame(model, state, dt=dt, dest=dest, walls=walls))
        state.velocities = state.velocities + out.accelerations * dt
        state.positions = state.positions + state.velocities * dt
        return out

    for _ in range(2):
        out = step(coarse_model, coarse, 0.1)
        np.testing.assert_allclose(sum(out.forces.values()), out.accelerations, atol=1e-12)
        for _ in range(5):
            step(fine_model, fine, 0.02)
        np.testing.assert_allclose(coarse.positions, fine.positions, atol=1e-12)
    assert np.any(out.forces["carry"] != 0.0)  # the true velocity was carried over


def test_inactive_zero_deterministic_inputs_kept():
    rng = np.random.default_rng(2)
    n = 30
    s = make_state(rng.uniform(0, 8, (n, 2)), vmax=1.2, velocities=rng.normal(0, 0.4, (n, 2)))
    dest = rng.uniform(0, 8, (n, 2))
    active = rng.random(n) < 0.7
    walls = (np.array([[0.0, 0.0], [0.0, 0.0]]), np.array([[8.0, 0.0], [0.0, 8.0]]))
    model = DeepSocialForce()
    frame = make_frame(model, s, dt=0.1, dest=dest, active=active, walls=walls)
    kept = [x.copy() for x in (s.positions, s.velocities, frame.destinations, frame.active)]
    a = model.compute(frame)
    b = DeepSocialForce().compute(frame)
    assert np.array_equal(a.accelerations, b.accelerations)
    assert np.all(a.accelerations[~active] == 0.0) and np.any(a.accelerations[active] != 0.0)
    np.testing.assert_allclose(sum(a.forces.values()), a.accelerations, atol=1e-12)
    for x, y in zip(kept, (s.positions, s.velocities, frame.destinations, frame.active),
                    strict=True):  # fmt: skip
        assert np.array_equal(x, y)


def _head_on(potential: str, offset: float) -> tuple[float, np.ndarray]:
    """Two pedestrians walking at each other 100 steps of 0.1 s; (closest distance, final)."""
    model = DeepSocialForce(DeepSocialForce.Params(potential=potential))
    s = make_state([[0.0, 0.0], [8.0, offset]], vmax=1.2)
    dest = np.array([[8.0, 0.0], [0.0, offset]])
    closest = np.inf
    for _ in range(100):
        acc = model.compute(make_frame(model, s, dt=0.1, dest=dest)).accelerations
        v = s.velocities + acc * 0.1
        v *= np.minimum(1.0, 1.2 / np.maximum(np.hypot(*v.T), 1e-12))[:, None]
        s.velocities = v
        s.positions = s.positions + v * 0.1
        closest = min(closest, float(np.hypot(*(s.positions[0] - s.positions[1]))))
    return closest, s.positions


def test_head_on_mlp_reproduces_generator_behaviour():
    """The learned potential walks like the analytic one it was trained on.

    Helbing–Molnár's (2.1 m²/s², 0.3 m) potential is soft: with 0.3 m lateral offset the
    pedestrians pass with about 0.48 m between centres (no body radius in this model).
    """
    mlp_closest, mlp_final = _head_on("mlp", 0.3)
    ref_closest, ref_final = _head_on("analytic", 0.3)
    assert mlp_closest == pytest.approx(ref_closest, abs=0.02)
    np.testing.assert_allclose(mlp_final, ref_final, atol=0.05)
    assert mlp_closest > 0.4  # they deviate: 0.3 m offset, ≥ 0.4 m at the closest
    assert mlp_final[0, 0] > 7.5 and mlp_final[1, 0] < 0.5  # and both get past


# -- packaging --------------------------------------------------------------------------------


def test_module_does_not_import_torch():
    tree = ast.parse(inspect.getsource(dsf_module))
    names = [
        a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names
    ] + [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    assert not any(n.split(".")[0] == "torch" for n in names)


def test_runs_without_torch_installed():
    code = (
        "import sys; sys.modules['torch'] = None\n"  # makes any `import torch` fail
        "import numpy as np\n"
        "from arena.crowd.models.deep_social_force import DeepSocialForce\n"
        "from arena.testing.conformance import check_crowd_model\n"
        "check_crowd_model(DeepSocialForce)\n"
        "assert sys.modules['torch'] is None\n"
        "print('ok')\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0 and "ok" in res.stdout, res.stderr


def test_registered_with_arena_analytic_option():
    assert "deep_social_force" in CROWD_MODELS.names("learned")
    m = CROWD_MODELS.build({"type": "deep_social_force", "potential": "analytic", "sigma": 1.0})
    assert isinstance(m, DeepSocialForce) and m.mlp is None


def test_conformance():
    check_crowd_model(DeepSocialForce)

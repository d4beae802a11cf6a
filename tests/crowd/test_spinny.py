"""Arena's ``spinny`` demo: pedsim's force rotated by k·angle at step k."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from arena.crowd.base import CROWD_MODELS, CrowdFrame, RobotView
from arena.crowd.models.pedsim.model import TERMS, PedsimModel
from arena.crowd.models.spinny import SpinnyModel
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld
from tests.crowd.test_pedsim import make_frame, room_walls


def rotated(v: np.ndarray, deg: float) -> np.ndarray:
    """Rows of ``v`` turned counter-clockwise by ``deg`` degrees."""
    a = math.radians(deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return v @ rot.T


def scene(seed: int = 0, t: float = 0.0) -> CrowdFrame:
    """Twelve agents (agent 3 inactive), a robot and walls, in an 8 m room."""
    rng = np.random.default_rng(1)
    robots = RobotView(np.array([[4.0, 4.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.4]))
    return make_frame(
        rng.uniform(0.5, 7.5, (12, 2)),
        rng.normal(0, 0.5, (12, 2)),
        rng.uniform(0.5, 7.5, (12, 2)),
        active=np.arange(12) != 3,
        robots=robots,
        walls=room_walls(8.0),
        seed=seed,
        time=t,
    )


def test_registered_as_a_demo_with_pedsims_params() -> None:
    assert CROWD_MODELS.get("spinny") is SpinnyModel
    assert CROWD_MODELS.entry("spinny").tags == ("demo",)
    p = SpinnyModel().params
    assert p.angle_per_step_deg == 3.0 and p.force_factor_social == 2.1
    built = CROWD_MODELS.build({"type": "spinny", "angle_per_step_deg": 10.0}, path="crowd")
    assert built.params.angle_per_step_deg == 10.0
    with pytest.raises(ValidationError):
        SpinnyModel.Params(angle=3.0)  # type: ignore[call-arg]


def test_output_is_pedsim_rotated_by_k_angles_after_k_steps() -> None:
    params = {"force_factor_random": 0.0}
    spinny = SpinnyModel(SpinnyModel.Params(**params))
    pedsim = PedsimModel(PedsimModel.Params(**params))
    fr = scene()
    base = pedsim.compute(fr)
    assert base.accelerations is not None
    for k in range(1, 6):
        out = spinny.compute(fr)
        assert spinny.steps == k
        assert out.accelerations is not None
        expected = rotated(base.accelerations, 3.0 * k)
        assert np.allclose(out.accelerations, expected, rtol=1e-12, atol=1e-12)
        # Rotation keeps lengths and turns every named term the same way.
        assert np.allclose(
            np.linalg.norm(out.accelerations, axis=1), np.linalg.norm(base.accelerations, axis=1)
        )
        for name in TERMS:
            assert np.allclose(out.forces[name], rotated(base.forces[name], 3.0 * k), atol=1e-12)
        total = sum((out.forces[name] for name in TERMS), np.zeros_like(out.accelerations))
        assert np.allclose(out.accelerations, total, atol=1e-12)
        assert np.array_equal(out.accelerations[3], np.zeros(2))  # inactive stays at zero


def test_full_turn_after_120_steps_and_reset_restarts() -> None:
    spinny = SpinnyModel(SpinnyModel.Params(force_factor_random=0.0))
    fr = scene()
    first = spinny.compute(fr).accelerations
    for _ in range(119):
        last = spinny.compute(fr).accelerations
    assert last is not None and first is not None
    base = PedsimModel(PedsimModel.Params(force_factor_random=0.0)).compute(fr).accelerations
    assert np.allclose(last, base, atol=1e-12)  # 120·3° = 360°
    spinny.reset(fr.state, StaticWorld.build(OccupancyGrid.empty(8.0, 8.0, 0.1)), fr.rng)
    assert spinny.steps == 0
    again = spinny.compute(fr).accelerations
    assert again is not None and np.allclose(again, first, atol=1e-12)


def test_zero_angle_is_pedsim_bit_for_bit_including_the_random_term() -> None:
    spinny = SpinnyModel(SpinnyModel.Params(angle_per_step_deg=0.0))
    pedsim = PedsimModel()
    for t in (0.0, 0.1):
        a = spinny.compute(scene(seed=4, t=t)).accelerations
        b = pedsim.compute(scene(seed=4, t=t)).accelerations
        assert a is not None and b is not None
        assert np.array_equal(a, b)


def test_agents_walk_in_circles() -> None:
    # One agent, integrated like the simulator (v += a·dt, hard cap, p += v·dt): with pedsim it
    # reaches its goal; with spinny it turns away and ends up nowhere near it.
    def run(model: PedsimModel) -> float:
        fr = make_frame([[1.0, 1.0]], [[0.0, 0.0]], [[9.0, 1.0]], vmax=1.0)
        s = fr.state
        for _ in range(100):
            out = model.compute(fr)
            assert out.accelerations is not None
            v = s.velocities + out.accelerations * fr.dt
            speed = np.linalg.norm(v, axis=1, keepdims=True)
            v = v * np.minimum(1.0, s.vmax[:, None] / np.maximum(speed, 1e-12))
            s.positions = s.positions + v * fr.dt
            s.velocities = v
            s.time += fr.dt
        return float(np.linalg.norm(s.positions[0] - [9.0, 1.0]))

    quiet = {"force_factor_random": 0.0}
    assert run(PedsimModel(PedsimModel.Params(**quiet))) < 0.5
    assert run(SpinnyModel(SpinnyModel.Params(**quiet))) > 3.0

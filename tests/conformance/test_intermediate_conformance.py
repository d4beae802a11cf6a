"""Conformance: every registered intermediate planner, run on a scripted sequence of inputs."""

import math

import numpy as np
import pytest

import arena.plugins  # noqa: F401
from arena.nav.intermediate import (
    INTERMEDIATE_PLANNERS,
    IntermediateInput,
    IntermediateOutput,
    IntermediatePlanner,
    Pedestrians,
)

PATH = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 6.0], [10.0, 6.0]])


def _inputs():
    """A robot driving along x while a crowd (an elder among them) walks toward it, with walls."""
    rng = np.random.default_rng(0)
    out = []
    for k in range(40):
        t = 0.1 * k
        pose = np.array([0.05 * k, 0.01 * k, 0.02 * k])
        peds = Pedestrians(
            positions=np.array([[3.0 - 0.1 * k, 0.2], [1.0, -3.0], [6.0, 4.0]]),
            velocities=np.array([[-1.0, 0.0], [0.0, 0.5], [0.0, 0.0]]),
            kinds=np.array([0, 1, 0]),
            states=np.array([1, 0, 1]),
        )
        walls = np.column_stack([np.linspace(-2, 12, 50), np.full(50, -1.5)])
        walls = walls + rng.normal(0, 0.01, walls.shape)
        out.append(
            IntermediateInput(
                pose=pose, twist=np.array([0.5, 0.0, 0.1]), path=PATH,
                goal=np.array([10.0, 6.0, 0.0]), max_speed=1.0, robot_radius=0.3,
                pedestrians=peds if k % 7 else Pedestrians(), obstacle_points=walls,
                window=3.0, time=t,
            )
        )
    return out


def _run(planner: IntermediatePlanner, inputs):
    planner.reset()
    return [planner.plan(inp) for inp in inputs]


def _snapshot(inp):
    return [
        np.array(a, copy=True)
        for a in (inp.pose, inp.twist, inp.path, inp.goal, inp.obstacle_points,
                  inp.pedestrians.positions, inp.pedestrians.velocities, inp.pedestrians.kinds)
    ]


@pytest.mark.parametrize("name", INTERMEDIATE_PLANNERS.names())
def test_intermediate_planner(name):
    planner = INTERMEDIATE_PLANNERS.build(name)
    assert isinstance(planner, IntermediatePlanner)
    inputs = _inputs()
    before = [_snapshot(i) for i in inputs]
    outs = _run(planner, inputs)
    for inp, snap, out in zip(inputs, before, outs, strict=True):
        # Inputs are never modified.
        for a, b in zip(_snapshot(inp), snap, strict=True):
            np.testing.assert_array_equal(a, b)
        assert isinstance(out, IntermediateOutput)
        path = np.asarray(out.path)
        assert path.ndim == 2 and path.shape[1] == 2 and len(path) >= 1
        assert np.all(np.isfinite(path))
        for key, value in out.overrides.items():
            assert isinstance(key, str)
            assert math.isfinite(value) and value >= 0
    # Deterministic, and reset forgets everything.
    again = _run(planner, inputs)
    for a, b in zip(outs, again, strict=True):
        np.testing.assert_array_equal(a.path, b.path)
        assert a.overrides == b.overrides
    # The same inputs to a fresh instance give the same outputs.
    fresh = _run(INTERMEDIATE_PLANNERS.build(name), inputs)
    for a, b in zip(outs, fresh, strict=True):
        np.testing.assert_array_equal(a.path, b.path)
        assert a.overrides == b.overrides


def test_bypass_is_identity():
    planner = INTERMEDIATE_PLANNERS.build("bypass")
    for inp in _inputs():
        out = planner.plan(inp)
        assert out.path is inp.path
        assert out.overrides == {}


def test_every_planner_handles_an_empty_world():
    inp = IntermediateInput(
        pose=np.zeros(3), twist=np.zeros(3), path=np.zeros((0, 2)),
        goal=np.array([1.0, 0.0, 0.0]), max_speed=0.5, robot_radius=0.2,
    )
    for name in INTERMEDIATE_PLANNERS.names():
        out = INTERMEDIATE_PLANNERS.build(name).plan(inp)
        assert np.all(np.isfinite(np.asarray(out.path).reshape(-1, 2)))
        assert out.overrides == {}

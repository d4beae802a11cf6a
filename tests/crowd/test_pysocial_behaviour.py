"""``pysocial`` behaviour: registration, term sums, groups, robots, cutoffs, conformance.

The force terms against PyPI ``pysocialforce`` and the compiled kernels against their plain
formulations are checked in ``test_pysocial.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from arena.crowd.base import CROWD_MODELS, RobotView
from arena.crowd.models.pysocial.model import TERMS, PySocialModel
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld
from arena.testing.conformance import check_crowd_model
from tests.crowd.pysocial_kit import EXACT, make_frame, make_state, ours, random_scene


# -- behaviour ------------------------------------------------------------------------------------
def test_registered_with_tags_and_frozen_params() -> None:
    assert CROWD_MODELS.get("pysocial") is PySocialModel
    assert "pysocial" in CROWD_MODELS.names("social_force")
    assert "pysocial" in CROWD_MODELS.names("default")
    model = CROWD_MODELS.build({"type": "pysocial", "force_scale": 0.3})
    assert model.params.force_scale == 0.3
    assert model.neighbor_cutoff() == PySocialModel.Params().cutoff
    with pytest.raises(ValidationError):
        PySocialModel.Params(not_a_param=1.0)
    with pytest.raises(ValidationError):
        PySocialModel.Params().social_factor = 1.0  # type: ignore[misc]


def test_terms_sum_to_accelerations_and_force_scale_scales() -> None:
    world, state, dest = random_scene(2, 20)
    robots = RobotView(np.array([[8.0, 6.0]]), np.zeros(1), np.array([[0.5, 0.0]]), np.full(1, 0.3))
    frame = make_frame(state, dest, robots=robots, search=10.0)
    out = ours(world, frame)
    assert set(out.forces) == set(TERMS)
    np.testing.assert_allclose(sum(out.forces.values()), out.accelerations, atol=1e-12)
    scaled = ours(world, frame, force_scale=0.3)
    np.testing.assert_allclose(scaled.accelerations, 0.3 * out.accelerations, rtol=1e-12)
    for name in TERMS:
        np.testing.assert_allclose(scaled.forces[name], 0.3 * out.forces[name], rtol=1e-12)


def test_inactive_agents_get_zero_but_still_repel_and_count_in_groups() -> None:
    world, state, dest = random_scene(4, 24)
    active = np.ones(24, dtype=bool)
    active[[0, 5, 9, 13]] = False
    everyone = ours(world, make_frame(state, dest, search=10.0))
    out = ours(world, make_frame(state, dest, active=active, search=10.0))
    assert np.all(out.accelerations[~active] == 0.0)
    for name in TERMS:
        assert np.all(out.forces[name][~active] == 0.0), name
    np.testing.assert_allclose(
        out.accelerations[active], everyone.accelerations[active], rtol=1e-12, atol=1e-12
    )


def test_inputs_are_not_mutated_and_results_deterministic() -> None:
    world, state, dest = random_scene(5, 25)
    robots = RobotView(np.array([[4.0, 4.0]]), np.zeros(1), np.array([[0.3, 0.1]]), np.full(1, 0.3))
    frame = make_frame(state, dest, robots=robots, search=10.0)
    kept = state.copy()
    kept_frame = {k: np.copy(getattr(frame, k)) for k in ("destinations", "active")}
    kept_nb = (frame.neighbors.indptr.copy(), frame.neighbors.indices.copy())
    kept_robots = (robots.positions.copy(), robots.velocities.copy())
    model = PySocialModel()
    model.reset(state, world, np.random.default_rng(0))
    first = model.compute(frame)
    again = model.compute(frame)  # reused work arrays
    fresh = ours(world, frame)
    for k, v in kept.__dict__.items():
        if isinstance(v, np.ndarray):
            np.testing.assert_array_equal(getattr(state, k), v, err_msg=k)
    for k, v in kept_frame.items():
        np.testing.assert_array_equal(getattr(frame, k), v)
    np.testing.assert_array_equal(frame.neighbors.indptr, kept_nb[0])
    np.testing.assert_array_equal(frame.neighbors.indices, kept_nb[1])
    np.testing.assert_array_equal(robots.positions, kept_robots[0])
    np.testing.assert_array_equal(robots.velocities, kept_robots[1])
    for other in (again, fresh):
        np.testing.assert_array_equal(first.accelerations, other.accelerations)
        for name in TERMS:
            np.testing.assert_array_equal(first.forces[name], other.forces[name])


def test_group_coherence_pulls_towards_the_centre_of_mass() -> None:
    pos = np.array([[0.0, 0.0], [4.0, 0.0], [2.0, 3.0], [10.0, 10.0]])
    state = make_state(pos, np.zeros((4, 2)), groups=[0, 0, 0, -1])
    dest = pos + np.array([20.0, 0.0])
    com = pos[:3].mean(axis=0)
    out = ours(None, make_frame(state, dest))
    # PySocialForce's gain: (tanh(0 − (k − 1)/2) + 1)/2, its distance being always 0.
    gain = (math.tanh(-1.0) + 1.0) / 2.0
    np.testing.assert_allclose(
        out.forces["group_coherence"][:3], gain * (com - pos[:3]), rtol=1e-12
    )
    fixed = ours(None, make_frame(state, dest), coherence_uses_distance=True)
    dist = np.linalg.norm(com - pos[:3], axis=1, keepdims=True)
    np.testing.assert_allclose(
        fixed.forces["group_coherence"][:3],
        (np.tanh(dist - 1.0) + 1.0) / 2.0 * (com - pos[:3]),
        rtol=1e-12,
    )
    for name in ("group_coherence", "group_repulsion", "group_gaze"):
        assert np.all(out.forces[name][3] == 0.0), "loners feel no group terms"


def test_group_repulsion_pushes_close_members_apart() -> None:
    pos = np.array([[0.0, 0.0], [0.4, 0.0], [5.0, 0.0], [5.6, 0.0]])
    state = make_state(pos, np.zeros((4, 2)), groups=[0, 0, 1, 1])
    out = ours(None, make_frame(state, pos + np.array([0.0, 10.0])))
    rep = out.forces["group_repulsion"]
    np.testing.assert_allclose(rep[:2], [[-0.4, 0.0], [0.4, 0.0]], atol=1e-15)
    assert np.all(rep[2:] == 0.0), "0.6 m apart is beyond the 0.55 m threshold"


def test_group_gaze_holds_back_the_leader_and_hurries_the_trailer() -> None:
    pos = np.array([[0.0, 0.0], [1.5, 0.0]])
    state = make_state(pos, np.zeros((2, 2)), groups=[0, 0])
    dest = pos + np.array([10.0, 0.0])  # both walk towards +x; member 1 is ahead
    gaze = ours(None, make_frame(state, dest)).forces["group_gaze"]
    assert gaze[0, 0] > 0 and gaze[1, 0] < 0
    np.testing.assert_allclose(gaze[:, 1], 0.0, atol=1e-15)
    # |c − r|·cos/|g − r|·ê = 1.5·(±1)/10
    np.testing.assert_allclose(gaze[:, 0], [0.15, -0.15], rtol=1e-12)
    on_goal = ours(None, make_frame(state, pos.copy())).forces["group_gaze"]
    assert np.all(on_goal == 0.0), "standing on the destination: 0, not NaN"


def test_robots_act_like_pedestrians_in_the_social_term() -> None:
    world, state, dest = random_scene(6, 15)
    rpos = np.array([[5.0, 5.0], [11.0, 7.0]])
    rvel = np.array([[0.6, -0.2], [-0.4, 0.3]])
    robots = RobotView(rpos, np.zeros(2), rvel, np.full(2, 0.3))
    with_robots = ours(
        world, make_frame(state, dest, robots=robots), **{**EXACT, "robot_factor": 1.0}
    )
    # The same robots appended as pedestrians: their social pull on the agents is the robot term.
    crowd = make_state(
        np.r_[state.positions, rpos],
        np.r_[state.velocities, rvel],
        groups=np.r_[state.group, [-1, -1]],
    )
    as_peds = ours(None, make_frame(crowd, np.r_[dest, rpos]), **EXACT)
    alone = ours(None, make_frame(state, dest), **EXACT)
    np.testing.assert_allclose(
        with_robots.forces["robot"],
        as_peds.forces["social"][:15] - alone.forces["social"],
        rtol=1e-9,
        atol=1e-12,
    )
    assert np.abs(with_robots.forces["robot"]).max() > 0
    off = ours(world, make_frame(state, dest, robots=robots), **EXACT)
    assert np.all(off.forces["robot"] == 0.0)
    np.testing.assert_array_equal(
        off.accelerations, ours(world, make_frame(state, dest), **EXACT).accelerations
    )


def test_robot_in_the_way_pushes_an_agent_aside() -> None:
    state = make_state(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
    robots = RobotView(
        np.array([[2.0, 0.1]]), np.zeros(1), np.array([[-0.5, 0.0]]), np.full(1, 0.3)
    )
    out = ours(None, make_frame(state, np.array([[10.0, 0.0]]), robots=robots))
    f = out.forces["robot"][0]
    assert f[0] < 0, "brakes"
    assert f[1] < 0, "sidesteps away from the robot (which is slightly to the left)"


def test_cutoff_and_neighbour_lists() -> None:
    world, state, dest = random_scene(8, 20, size=(8.0, 6.0))
    exact = ours(world, make_frame(state, dest), **EXACT)
    within = ours(world, make_frame(state, dest, search=10.0), **{**EXACT, "cutoff": 10.0})
    np.testing.assert_allclose(within.accelerations, exact.accelerations, rtol=1e-12, atol=1e-12)
    # A wider neighbour search than the model's cutoff gives the same as the matching search.
    short = {**EXACT, "cutoff": 2.0}
    wide = ours(world, make_frame(state, dest, search=math.inf), **short)
    tight = ours(world, make_frame(state, dest, search=2.0), **short)
    np.testing.assert_allclose(wide.accelerations, tight.accelerations, rtol=1e-12, atol=1e-12)
    assert not np.allclose(tight.forces["social"], exact.forces["social"])


def test_per_agent_radius_option() -> None:
    world, state, dest = random_scene(9, 12)
    state.radii = np.full(12, 0.35)
    frame = make_frame(state, dest, search=10.0)
    np.testing.assert_allclose(
        ours(world, frame, agent_radius=None).accelerations,
        ours(world, frame).accelerations,
        rtol=1e-12,
    )
    state.radii = np.full(12, 0.2)
    smaller = ours(world, make_frame(state, dest, search=10.0), agent_radius=None)
    assert not np.allclose(smaller.forces["obstacle"], ours(world, frame).forces["obstacle"])


def test_no_agents_and_no_walls() -> None:
    state = make_state(np.zeros((0, 2)), np.zeros((0, 2)))
    out = ours(
        StaticWorld.build(OccupancyGrid.empty(4.0, 4.0, 0.1)), make_frame(state, np.zeros((0, 2)))
    )
    assert out.accelerations.shape == (0, 2)
    lone = make_state(np.array([[1.0, 1.0]]), np.zeros((1, 2)))
    out = ours(None, make_frame(lone, np.array([[3.0, 1.0]])))
    np.testing.assert_allclose(out.accelerations, [[1.2 / 0.5, 0.0]])  # desired only


def test_passes_the_crowd_model_conformance_checks() -> None:
    check_crowd_model(PySocialModel)

"""BRNE: a distribution per agent, the Nash iteration lowers the expected collision cost, it
passes a head-on pedestrian with a gap, goes straight on an empty road, is deterministic and
reaches the goal among people."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.nav.local_planners import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.brne import BrnePlanner
from arena.nav.local_planners.brne_kernels import (
    expected_cost,
    gp_cholesky,
    gp_perturbations,
    nash_weights,
    pair_costs,
)
from arena.robots.kinematics import integrate_twist
from arena.robots.limits import VelocityLimits
from arena.testing import check_local_planner
from tests.nav.planner_kit import DIFF, DRIVES, DT, RADIUS, wall_scan

PED_RADIUS = BrnePlanner.Params().pedestrian_radius
GO1 = VelocityLimits(-0.8, 0.8, -0.8, 0.8, 1.2, 1.25, 1.25, 1.0)  # the go1 preset's box
PATH = np.stack([np.linspace(0.0, 10.0, 100), np.zeros(100)], axis=-1)


def _obs(pose, twist, lim, kin, peds=None, **kw) -> LocalObservation:
    return LocalObservation(
        pose=np.asarray(pose, dtype=float), twist=np.asarray(twist, dtype=float),
        goal=Pose2D(10.0, 0.0), path=PATH, limits=lim, robot_radius=RADIUS, dt=DT,
        kinematics=kin, pedestrians=np.zeros((0, 4)) if peds is None else np.asarray(peds),
        **kw,
    )


def _head_on(planner, lim: VelocityLimits, kin: str, ticks: int = 200):
    """A person walks at 0.8 m/s straight at the robot on its path; commands, poses, gaps."""
    pose, twist = np.zeros(3), np.zeros(3)
    ped, vel = np.array([5.0, 0.0]), np.array([-0.8, 0.0])
    cmds, poses, gaps = [], [], []
    for _ in range(ticks):
        cmd = planner.compute(_obs(pose, twist, lim, kin, [[*ped, *vel]]))
        pose, twist = integrate_twist(pose[None], cmd[None], DT)[0], cmd
        ped = ped + vel * DT
        cmds.append(cmd)
        poses.append(pose)
        gaps.append(float(np.hypot(*(pose[:2] - ped))))
        if np.hypot(*(pose[:2] - PATH[-1])) < 0.1:
            break
    return np.array(cmds), np.array(poses), np.array(gaps)


def test_conformance() -> None:
    check_local_planner(lambda: LOCAL_PLANNERS.build({"type": "brne"}))


def test_weights_are_distributions_and_the_nash_iteration_lowers_the_expected_cost() -> None:
    rng = np.random.default_rng(3)
    times = np.arange(1, 16) * 0.2
    pert = gp_perturbations(gp_cholesky(times, 1.6, 1.0), 4, 60, rng) * 0.5
    # Four agents crossing the origin from four sides at 0.8 m/s.
    starts = np.array([[-2.0, 0.0], [2.0, 0.0], [0.0, -2.0], [0.0, 2.0]])
    nominal = starts[:, None] - 0.8 * times[None, :, None] * np.sign(starts)[:, None]
    samples = nominal[:, None] + pert
    xs = np.ascontiguousarray(samples[..., 0].transpose(0, 2, 1))
    ys = np.ascontiguousarray(samples[..., 1].transpose(0, 2, 1))
    costs, active = pair_costs(xs, ys, np.full(4, 0.3), 0.5, 20.0)
    eye = np.eye(4, dtype=bool)
    assert active[~eye].all() and not active[eye].any()
    np.testing.assert_array_equal(costs, costs.transpose(2, 3, 0, 1))  # symmetric
    for a in range(4):
        assert not costs[a, :, a].any()
    prior = np.ones((4, 60))
    uniform = prior / 60
    before = expected_cost(costs, uniform)
    weights = nash_weights(costs, active, prior, 10)
    assert np.all(weights >= 0)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-12)
    assert before > 1.0  # they would collide without the game
    assert expected_cost(costs, weights) < 0.2 * before
    # Fewer sweeps lower it less; a zero prior stays zero.
    assert expected_cost(costs, nash_weights(costs, active, prior, 1)) > expected_cost(
        costs, weights
    ) - 1e-9
    masked = prior.copy()
    masked[0, :30] = 0.0
    assert not nash_weights(costs, active, masked, 10)[0, :30].any()


def test_solution_of_a_tick_is_consistent() -> None:
    planner = BrnePlanner()
    peds = [[3.0, 0.2, -0.8, 0.0], [2.0, -1.5, 0.0, 0.7], [9.0, 9.0, 0.0, 0.0]]
    sol = planner.solve(_obs(np.zeros(3), np.zeros(3), DIFF, "diff_drive", peds), 1.0)
    np.testing.assert_array_equal(sol.people, [1, 0])  # nearest first, the far one left out
    m = planner.params.samples
    assert sol.samples.shape == (3, m, planner.params.steps, 2)
    np.testing.assert_allclose(sol.weights.sum(axis=1), 1.0)
    np.testing.assert_allclose(sol.plan, np.einsum("m,mtk->tk", sol.weights[0], sol.samples[0]))
    # Every agent's sample 0 is its nominal; people's nominals are constant-velocity.
    np.testing.assert_allclose(sol.samples[1, 0], [2.0, -1.5] + sol.times[:, None] * [0.0, 0.7])
    # With uniform weights the plan would be the nominal: the perturbations average to zero.
    np.testing.assert_allclose(sol.samples[0].mean(axis=0), sol.samples[0, 0], atol=1e-12)


@pytest.mark.parametrize(("lim", "kin"), [(DIFF, "diff_drive"), (DRIVES["omni"], "omni"),
                                          (DRIVES["legged"], "legged"), (GO1, "legged")])
def test_passes_a_head_on_pedestrian_to_one_side_with_a_gap(lim: VelocityLimits, kin: str) -> None:
    _, poses, gaps = _head_on(BrnePlanner(), lim, kin)
    side = poses[np.argmax(np.abs(poses[:, 1])), 1]
    assert abs(side) > 0.5  # it deviated, to one side
    assert np.all(np.sign(poses[np.abs(poses[:, 1]) > 0.2, 1]) == np.sign(side))  # only that one
    assert gaps.min() > RADIUS + PED_RADIUS + 0.2
    assert np.hypot(*(poses[-1, :2] - PATH[-1])) < 0.1  # and reached the goal


def test_empty_scene_goes_straight_to_the_goal() -> None:
    planner = BrnePlanner(BrnePlanner.Params(alone="tracker"))
    pose, twist = np.zeros(3), np.zeros(3)
    ys = []
    for _ in range(150):
        cmd = planner.compute(_obs(pose, twist, DIFF, "diff_drive"))
        assert planner.last is None  # nobody near: no game, the path follower
        pose, twist = integrate_twist(pose[None], cmd[None], DT)[0], cmd
        ys.append(pose[1])
    assert np.max(np.abs(ys)) < 1e-9
    assert abs(pose[0] - 10.0) < 0.06


def test_alone_dwa_drives() -> None:
    """With nobody in the game the default hands the tick to DWA (its commands, unchanged)."""
    from arena.nav.local_planners.dwa import DWAPlanner

    brne, dwa = BrnePlanner(), DWAPlanner()
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(60):
        obs = _obs(pose, twist, DIFF, "diff_drive")
        cmd = brne.compute(obs)
        np.testing.assert_array_equal(cmd, dwa.compute(obs))
        pose, twist = integrate_twist(pose[None], cmd[None], DT)[0], cmd
    assert pose[0] > 1.0  # it drove toward the goal


def test_people_beyond_the_activation_radius_do_not_play() -> None:
    planner = BrnePlanner()
    far = [[20.0, 0.0, -1.0, 0.0]]
    cmd = planner.compute(_obs(np.zeros(3), np.zeros(3), DIFF, "diff_drive", far))
    assert planner.last is None
    np.testing.assert_array_equal(
        cmd, BrnePlanner().compute(_obs(np.zeros(3), np.zeros(3), DIFF, "diff_drive"))
    )


def test_samples_through_a_wall_are_dropped() -> None:
    planner = BrnePlanner()
    # A wall across the path 2 m ahead, a person behind it: every sample reaching the wall drops.
    ranges, angles = wall_scan(np.zeros(3), 2.0)
    obs = _obs(np.zeros(3), np.zeros(3), DIFF, "diff_drive", [[3.5, 0.0, -0.5, 0.0]],
               scan_ranges=ranges, scan_angles=angles)
    sol = planner.solve(obs, 1.0)
    reach = sol.samples[0, :, :, 0].max(axis=1)
    hit = reach > 2.0 - RADIUS - planner.params.obstacle_margin + 0.02
    assert hit.any() and (~hit).any()
    assert not sol.prior[0, hit].any() and not sol.weights[0, hit].any()
    assert sol.plan[:, 0].max() < 2.0 - RADIUS


def test_deterministic_and_seeded() -> None:
    a, _, _ = _head_on(BrnePlanner(), DIFF, "diff_drive", ticks=60)
    b, _, _ = _head_on(BrnePlanner(), DIFF, "diff_drive", ticks=60)
    np.testing.assert_array_equal(a, b)
    planner = BrnePlanner()
    _head_on(planner, DIFF, "diff_drive", ticks=30)
    planner.reset()
    c, _, _ = _head_on(planner, DIFF, "diff_drive", ticks=60)
    np.testing.assert_array_equal(a, c)
    other = BrnePlanner(BrnePlanner.Params(seed=1))
    d, _, _ = _head_on(other, DIFF, "diff_drive", ticks=60)
    assert not np.array_equal(a, d)


def test_params_are_validated() -> None:
    with pytest.raises(ConfigError, match="samples"):
        LOCAL_PLANNERS.build({"type": "brne", "samples": 1})
    with pytest.raises(ConfigError, match="warm_start"):
        LOCAL_PLANNERS.build({"type": "brne", "warm_start": 1.0})


@pytest.mark.parametrize("robot", ["go1", "jackal"])
def test_reaches_the_goal_in_canteens_with_people(robot: str) -> None:
    from arena.config.loader import load_config
    from arena.experiment import run_episode
    from arena.sim.backend import BACKENDS
    from arena.tasks.generator import TaskGenerator

    cfg = load_config(None, [
        f"robot={robot}", "seed=7", "task.timeout=60", "task.goal_tolerance_angle=null",
        "output.video=false", "map.type=canteen", "task.obstacles.static=0",
        "task.obstacles.dynamic=10", "task.robots.min_goal_distance=10",
        "task.modules=[{type: dynamic_map, episodes_per_map: 1}]",
        "navigation.local_planner.type=brne",
    ])
    gen = TaskGenerator.from_config(cfg)
    outcomes = []
    for index in (1, 2):
        episode = gen.episode(index)
        res = run_episode(cfg, episode, BACKENDS.build(cfg.sim.backend), None,
                          runtime=gen.runtime(episode))
        outcomes.append(res.outcome)
        assert math.isfinite(res.control_ms_mean)
    assert outcomes == ["success", "success"]

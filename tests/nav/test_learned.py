"""The rosnav_rl local planner: a freshly initialised, exported PPO policy drives the robot."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from arena.core.errors import ConfigError
from arena.learn.env import SocialNavEnv
from arena.learn.observations import goal_polar
from arena.learn.planners.learned import LearnedPlanner, resample_scan
from arena.learn.policy import NumpyPolicy, export_policy
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.path_tracking import finish_command
from tests.learn.helpers import small_cfg, small_robot

BEAMS = 16
# 3 m along the path [[1, 2], [3, 2], [6, 5]] from its start
SUBGOAL = np.array([[3.0 + np.sqrt(0.5), 2.0 + np.sqrt(0.5)]])


def _export(tmp_path, *overrides, stack=1):
    robot = small_robot(BEAMS)
    cfg = small_cfg(f"learning.env.observation.laser_stack={stack}", *overrides)
    env = SocialNavEnv(cfg, robot=robot)
    venv = VecNormalize(DummyVecEnv([lambda: env]), norm_reward=False)
    model = PPO("MultiInputPolicy", venv, n_steps=8, batch_size=8, seed=0, device="cpu")
    venv.reset()
    for _ in range(5):  # some normalisation statistics
        venv.step(np.array([venv.action_space.sample()]))
    path = export_policy(model, venv, tmp_path / "p.npz", decoder=env.driver.decoder,
                         laser=robot.laser)
    return path, robot


def _obs(robot, rng, twist=None):
    lim = robot.limits()
    return LocalObservation(
        pose=np.array([1.0, 2.0, rng.uniform(-np.pi, np.pi)]),
        twist=np.zeros(3) if twist is None else twist,
        goal=np.array([6.0, 5.0, 0.0]),
        path=np.array([[1.0, 2.0], [3.0, 2.0], [6.0, 5.0]]),
        limits=lim,
        robot_radius=robot.radius,
        dt=0.1,
        scan_ranges=rng.uniform(0.2, 12.0, BEAMS),
        scan_angles=robot.laser.angles(),
    )


@pytest.mark.parametrize("action", ["discrete", "continuous"])
def test_planner_equals_numpy_policy_within_limits(tmp_path, action):
    extra = ("learning.env.action.type=continuous",) if action == "continuous" else ()
    path, robot = _export(tmp_path, *extra, stack=2)
    planner = LOCAL_PLANNERS.build({"type": "rosnav_rl", "weights": str(path),
                                    "subgoal_horizon": 3.0})
    assert isinstance(planner, LearnedPlanner)
    pol = NumpyPolicy.load(path)
    rng = np.random.default_rng(0)
    lim = robot.limits()
    twist = np.zeros(3)
    scans = []
    for _ in range(20):
        o = _obs(robot, rng, twist)
        prev = twist.copy()
        cmd = planner.compute(o)
        scans.append(np.clip(o.scan_ranges, 0, robot.laser.range_max))
        expect_obs = {
            "lidar": np.stack(scans[-2:] if len(scans) > 1 else scans * 2).astype(np.float32),
            "goal": goal_polar(o.pose[None], SUBGOAL)[0].astype(np.float32),
            "last_action": prev.astype(np.float32),
        }
        expect = finish_command(pol.command(pol.act(expect_obs)), prev, lim, 0.1, False)
        np.testing.assert_allclose(cmd, expect, atol=1e-6)
        assert np.all(cmd >= np.array([lim.vx_min, 0.0, -lim.omega_max]) - 1e-9)
        assert np.all(cmd <= np.array([lim.vx_max, 0.0, lim.omega_max]) + 1e-9)
        assert np.all(np.abs(cmd - prev) <= lim.acceleration * 0.1 + 1e-9)
        twist = cmd


def test_planner_errors(tmp_path):
    with pytest.raises(ConfigError, match="arena train"):
        LearnedPlanner(LearnedPlanner.Params(weights=str(tmp_path / "none.npz")))
    path, robot = _export(tmp_path)
    planner = LearnedPlanner(LearnedPlanner.Params(weights=str(path)))
    o = _obs(robot, np.random.default_rng(1))
    other = LocalObservation(pose=o.pose, twist=o.twist, goal=o.goal, path=o.path,
                             limits=o.limits, robot_radius=o.robot_radius, dt=o.dt,
                             scan_ranges=np.ones(5), scan_angles=np.zeros(5))
    assert planner.compute(other).shape == (3,)  # another laser is resampled, not refused
    path2, _ = _export(tmp_path / "peds", "learning.env.observation.pedestrians.enabled=true")
    with pytest.raises(ConfigError, match="not supported"):
        LearnedPlanner(LearnedPlanner.Params(weights=str(path2)))


def test_resample_identity_and_layouts():
    rng = np.random.default_rng(3)
    for angles in (
        small_robot(BEAMS).laser.angles(),  # 270° scan
        np.linspace(-np.pi, np.pi, 360, endpoint=False),  # full circle
        np.array([0.3]),
    ):
        r = rng.uniform(0.0, 12.0, angles.size)
        np.testing.assert_array_equal(resample_scan(angles, r, angles, 30.0), r)
    tgt = np.linspace(-np.pi, np.pi, 8, endpoint=False)  # spacing π/4
    # no beams: all range_max; inf reads range_max; negative ranges clip to 0
    np.testing.assert_array_equal(resample_scan(np.zeros(0), np.zeros(0), tgt, 10.0),
                                  np.full(8, 10.0))
    # two beams in the bin of target 0 (π/4 ± π/8 → [π/8, 3π/8)): their minimum
    sa = np.array([np.pi / 4 - 0.1, np.pi / 4 + 0.2, np.pi, -np.pi / 2 + 0.01])
    sr = np.array([3.0, 2.0, np.inf, -1.0])
    out = resample_scan(sa, sr, tgt, 10.0)
    assert out[5] == 2.0  # tgt[5] = π/4
    assert out[0] == 10.0  # -π: a beam at π (inf) → range_max
    assert out[2] == 0.0  # -π/2 + 0.01: clipped
    # a sparse scan: targets without a beam in their bin take the nearest within one spacing
    sparse = resample_scan(np.array([0.0]), np.array([4.0]), tgt, 10.0)
    np.testing.assert_array_equal(sparse, [10, 10, 10, 4.0, 4.0, 4.0, 10, 10])


@pytest.mark.parametrize("beams", [0, 37, 720])
def test_planner_on_any_laser(tmp_path, beams):
    path, robot = _export(tmp_path)
    planner = LearnedPlanner(LearnedPlanner.Params(weights=str(path)))
    assert planner.beam_angles.size == BEAMS
    np.testing.assert_allclose(planner.beam_angles, robot.laser.angles())
    rng = np.random.default_rng(beams)
    o = _obs(robot, rng)
    spec = robot.laser.model_copy(update={"num_beams": max(beams, 1)})
    angles = spec.angles()[:beams]
    scan = LocalObservation(pose=o.pose, twist=o.twist, goal=o.goal, path=o.path,
                            limits=o.limits, robot_radius=o.robot_radius, dt=o.dt,
                            scan_ranges=rng.uniform(0.2, 12.0, beams), scan_angles=angles)
    lidar = planner.observation(scan)["lidar"]
    assert lidar.shape == (BEAMS,)  # one scan: (beams,), as SocialNavEnv gives it
    assert np.all((lidar >= 0) & (lidar <= robot.laser.range_max))
    if beams == 0:
        assert np.all(lidar == robot.laser.range_max)
    else:
        assert lidar.min() >= scan.scan_ranges.min() - 1e-6
    for _ in range(3):
        cmd = planner.compute(scan)
        assert cmd.shape == (3,) and np.all(np.isfinite(cmd))


def test_exported_meta_records_laser(tmp_path):
    path, robot = _export(tmp_path)
    meta = NumpyPolicy.load(path).meta["laser"]
    assert meta["range_max"] == robot.laser.range_max
    np.testing.assert_allclose(meta["angles"], robot.laser.angles())

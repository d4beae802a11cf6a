"""APPLR: parameter ranges, the planner's rhythm, numpy = torch, its env, the shipped policy."""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from arena.config import load_config  # noqa: E402
from arena.core.errors import ConfigError  # noqa: E402
from arena.core.types import Pose2D  # noqa: E402
from arena.experiment import run_experiment  # noqa: E402
from arena.learn.applr.actor import ApplrActor, save_actor  # noqa: E402
from arena.learn.applr.env import TRAIN_CONFIG, ApplrEnv  # noqa: E402
from arena.learn.applr.space import (  # noqa: E402
    CAPS,
    PARAMETERS,
    FeatureSpec,
    parameter_ranges,
    parameter_values,
    spread_beams,
)
from arena.learn.applr.train import (  # noqa: E402
    VALIDATION_OFFSET,
    ApplrTrainSettings,
    export,
    train,
)
from arena.learn.applr.tuned_dwa import TunedDWA, capped_limits  # noqa: E402
from arena.learn.planners.applr import APPLR_WEIGHTS, ApplrPlanner  # noqa: E402
from arena.nav.local_planners import LOCAL_PLANNERS  # noqa: E402
from arena.nav.local_planners.base import LocalObservation  # noqa: E402
from arena.nav.local_planners.dwa import DWAPlanner  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402
from arena.tasks.suite import load_suite, stage_run_seed  # noqa: E402

SUITE = Path(__file__).resolve().parents[2] / "arena" / "tasks" / "data" / "suites" / "barn.yaml"


def _random_actor(path: Path, seed: int, scale: float = 1.0) -> Path:
    """An untrained actor file (72 beams over the jackal's laser, 32-32 hidden units)."""
    rng = np.random.default_rng(seed)
    spec = FeatureSpec(spread_beams(-2.35619, 2.35619, 72))
    dims = [spec.size(len(PARAMETERS)), 32, 32, len(PARAMETERS)]
    ws = [rng.normal(0, scale / math.sqrt(a), (b, a)) for a, b in itertools.pairwise(dims)]
    bs = [rng.normal(0, 0.1, b) for b in dims[1:]]
    return save_actor(path, ws, bs, {"features": spec.to_json(),
                                     "parameters": parameter_ranges(), "period": 1.0})


def _obs(t: float, scan: np.ndarray, twist=(0.0, 0.0, 0.0)) -> LocalObservation:
    robot = load_robot("jackal")
    return LocalObservation(
        pose=np.zeros(3), twist=np.asarray(twist, dtype=float), goal=Pose2D(5.0, 0.0),
        path=np.array([[0.0, 0.0], [5.0, 0.0]]), limits=robot.limits(),
        robot_radius=robot.radius, dt=0.1, scan_ranges=scan,
        scan_angles=np.linspace(-2.35619, 2.35619, scan.size), time=t,
        kinematics="diff_drive",
    )


# -- parameter space ----------------------------------------------------------------------------


def test_any_action_maps_into_the_documented_ranges():
    rng = np.random.default_rng(0)
    actions = [rng.normal(0, 5, len(PARAMETERS)) for _ in range(200)]
    actions += [np.full(len(PARAMETERS), v) for v in (-1e9, 1e9, np.nan, np.inf, -np.inf)]
    tuned = TunedDWA()
    for a in actions:
        values = parameter_values(a)
        for p in PARAMETERS:
            assert p.low <= values[p.name] <= p.high, (p.name, values[p.name])
            if p.integer:
                assert values[p.name] == round(values[p.name])
        tuned.set_action(a)  # DWA validates every field it receives
        assert isinstance(tuned.dwa.params, DWAPlanner.Params)


def test_zero_action_is_dwa_with_its_defaults_and_ends_are_the_range_ends():
    values = parameter_values(np.zeros(len(PARAMETERS)))
    defaults = DWAPlanner.Params()
    for p in PARAMETERS:
        if p.name in CAPS:
            assert values[p.name] == 1.0  # no cap: the robot's own limits
        else:
            assert values[p.name] == getattr(defaults, p.name), p.name
    assert parameter_values(-np.ones(len(PARAMETERS))) == {p.name: p.low for p in PARAMETERS}
    assert parameter_values(np.ones(len(PARAMETERS))) == {p.name: p.high for p in PARAMETERS}
    for p in PARAMETERS:
        if not p.integer:
            for a in (-0.7, -0.2, 0.3, 0.9):
                assert p.action(p.value(a)) == pytest.approx(a) or p.high == p.default


def test_speed_caps_bound_the_command_and_never_ask_for_more_than_one_cycle_of_braking():
    lim = load_robot("jackal").limits()
    capped = capped_limits(lim, np.array([1.8, 0.0, 3.5]), 0.1, 0.2, 0.2)
    assert capped.vx_max == pytest.approx(max(0.2 * lim.vx_max, 1.8 - lim.acc_x * 0.1))
    assert capped.omega_max == pytest.approx(max(0.2 * lim.omega_max, 3.5 - lim.acc_omega * 0.1))
    slow = capped_limits(lim, np.zeros(3), 0.1, 0.2, 0.5)
    assert slow.vx_max == pytest.approx(0.2 * lim.vx_max)
    assert slow.omega_max == pytest.approx(0.5 * lim.omega_max)
    tuned = TunedDWA()
    tuned.set_action(np.r_[-1.0, -1.0, np.zeros(len(PARAMETERS) - 2)])
    twist = np.array([0.4, 0.0, 0.0])
    for _ in range(30):  # free road: accelerates up to the cap, never past it
        cmd = tuned.compute(_obs(0.0, np.full(720, 30.0), twist))
        assert cmd[0] <= 0.2 * lim.vx_max + 1e-9 and abs(cmd[2]) <= 0.2 * lim.omega_max + 1e-9
        twist = cmd
    assert twist[0] == pytest.approx(0.2 * lim.vx_max)


# -- the planner ----------------------------------------------------------------------------------


def test_planner_sets_dwa_parameters_once_per_period_not_every_cycle(tmp_path):
    path = _random_actor(tmp_path / "a.npz", seed=1, scale=3.0)
    planner = ApplrPlanner(ApplrPlanner.Params(weights=str(path)))
    rng = np.random.default_rng(2)
    changes, params = [], planner.tuned.dwa.params
    for k in range(31):
        t = round(0.1 * k, 10)
        planner.compute(_obs(t, rng.uniform(0.3, 3.0, 720)))
        if planner.tuned.dwa.params is not params:
            changes.append(t)
            params = planner.tuned.dwa.params
    # the first cycle drives with the defaults, the next chooses, then once per second
    assert changes == [0.1, 1.1, 2.1]
    assert planner.tuned.values != parameter_values(np.zeros(len(PARAMETERS)))
    planner.reset()
    assert planner.tuned.dwa.params == DWAPlanner.Params()


def test_missing_or_foreign_weights_fail_with_one_line(tmp_path):
    with pytest.raises(ConfigError, match="no APPLR policy file") as e:
        LOCAL_PLANNERS.build({"type": "applr", "weights": str(tmp_path / "none.npz")})
    assert "\n" not in str(e.value) and "navigation.local_planner.weights" in str(e.value)
    other = tmp_path / "other.npz"
    np.savez(other, w0=np.zeros((2, 2)))
    with pytest.raises(ConfigError, match="not an APPLR policy file") as e:
        ApplrPlanner(ApplrPlanner.Params(weights=str(other)))
    assert "\n" not in str(e.value)


def test_numpy_actor_equals_the_torch_actor(tmp_path):
    from stable_baselines3 import TD3

    env = ApplrEnv()
    model = TD3("MlpPolicy", env, policy_kwargs={"net_arch": [64, 64]}, seed=4, device="cpu",
                learning_starts=0, buffer_size=100)
    actor = export(model, env, tmp_path / "p.npz", {})
    x = np.random.default_rng(5).uniform(-1, 1, (16, env.observation_space.shape[0]))
    with torch.no_grad():
        expected = model.actor(torch.as_tensor(x, dtype=torch.float32)).numpy()
    np.testing.assert_allclose(actor.act(x), expected, atol=1e-5)
    predicted, _ = model.predict(x.astype(np.float32), deterministic=True)
    np.testing.assert_allclose(actor.act(x), predicted, atol=1e-5)


# -- the training env -----------------------------------------------------------------------------


def test_env_passes_gymnasiums_checker_and_is_deterministic():
    from gymnasium.utils.env_checker import check_env

    check_env(ApplrEnv(), skip_render_check=True)
    a, b = ApplrEnv(), ApplrEnv()
    oa, _ = a.reset(seed=3)
    ob, _ = b.reset(seed=3)
    np.testing.assert_array_equal(oa, ob)
    action = np.linspace(-1, 1, len(PARAMETERS))
    for _ in range(4):
        ra, rb = a.step(action), b.step(action)
        np.testing.assert_array_equal(ra[0], rb[0])
        assert ra[1:4] == rb[1:4]
        assert ra[4]["parameters"] == parameter_values(action)


def test_env_steps_in_the_planners_rhythm(tmp_path):
    """An env episode driven by an actor equals ``arena run`` with that actor as planner."""
    path = _random_actor(tmp_path / "a.npz", seed=6, scale=0.5)
    actor = ApplrActor.load(path)
    env = ApplrEnv()
    obs, _ = env.reset(seed=8)
    done, info = False, {}
    while not done:
        obs, _, term, trunc, info = env.step(actor.act(obs))
        done = term or trunc
    assert info["outcome"] == "success"  # an env episode ends at its first contact
    cfg = load_config(TRAIN_CONFIG, ["seed=8", f"navigation.local_planner={{type: applr, "
                                     f"weights: {path}}}"])
    _, results = run_experiment(cfg, tmp_path / "run")
    assert results[0].outcome == "success"
    assert results[0].time == pytest.approx(info["time"])
    end = env.runner.state.robots.poses[0]  # type: ignore[union-attr]
    np.testing.assert_allclose(results[0].record.pose[-1], end, atol=1e-9)


def test_training_episodes_are_not_held_out_ones():
    train_cfg = load_config(TRAIN_CONFIG)
    suite = load_suite(SUITE)
    assert train_cfg.map["type"] == suite.stages[0].map["type"] == "barn"
    held_out = {stage_run_seed(run_seed, seed) for run_seed in range(10) for seed in suite.seeds}
    # the trainer draws episodes from its own seed (it replaces the config's), validation
    # episodes from that seed + VALIDATION_OFFSET
    used = {train_cfg.seed, ApplrTrainSettings().seed}
    used |= {s + VALIDATION_OFFSET for s in used}
    assert used.isdisjoint(held_out)
    assert used.isdisjoint(suite.seeds)


def test_tiny_training_run_is_deterministic_and_exports_a_loadable_policy(tmp_path):
    s = ApplrTrainSettings(steps=40, learning_starts=20, batch_size=8, hidden=(16, 16),
                           eval_every=40, eval_episodes=1, seed=3)
    va = train(s, tmp_path / "a", log=lambda _: None)
    vb = train(s, tmp_path / "b", log=lambda _: None)
    np.testing.assert_equal(dataclasses.asdict(va), dataclasses.asdict(vb))  # NaN == NaN here
    pa, pb = ApplrActor.load(tmp_path / "a" / "policy.npz"), ApplrActor.load(
        tmp_path / "b" / "policy.npz")
    for wa, wb in zip(pa.weights, pb.weights, strict=True):
        np.testing.assert_array_equal(wa, wb)
    assert pa.meta["training"]["steps"] == 40 and pa.period == 1.0


# -- the shipped policy ---------------------------------------------------------------------------


def test_shipped_policy_is_small_and_records_its_training():
    assert APPLR_WEIGHTS.stat().st_size < 5_000_000
    actor = ApplrActor.load(APPLR_WEIGHTS)
    assert actor.meta["parameters"] == parameter_ranges()
    assert actor.period == 1.0 and actor.features.clip_range == 2.0
    training = actor.meta["training"]
    assert {"steps", "wall_time_s", "hardware", "command"} <= set(training)
    assert "learned" in LOCAL_PLANNERS.entry("applr").tags


def test_shipped_policy_reaches_the_goal_of_a_seeded_barn_episode(tmp_path):
    cfg = load_config(TRAIN_CONFIG, ["seed=77", "navigation.local_planner={type: applr}"])
    _, results = run_experiment(cfg, tmp_path)
    assert results[0].error == ""
    assert results[0].outcome == "success", results[0].outcome


def test_replaced_limits_leave_the_observation_alone():
    tuned = TunedDWA()
    tuned.set_action(-np.ones(len(PARAMETERS)))
    obs = _obs(0.0, np.full(720, 1.0))
    before = dataclasses.replace(obs)
    tuned.compute(obs)
    assert obs.limits == before.limits and tuned.last_obs is obs

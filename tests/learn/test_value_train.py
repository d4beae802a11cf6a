"""Training the value policies (arena.learn.value.train): targets and a tiny deterministic run."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

torch = pytest.importorskip("torch")

from arena.config import load_config  # noqa: E402
from arena.learn.value import load_value_policy  # noqa: E402
from arena.learn.value.train import EpisodeLog, TrainSettings, targets, train  # noqa: E402


def _straight_log(n: int, outcome: str, collide_at: int | None = None) -> EpisodeLog:
    """A robot driving +x at 1 m/s (= v_pref), local goal fixed at x = 2, ticks of 0.1 s."""
    log = EpisodeLog(outcome=outcome)
    for k in range(n):
        x = 0.1 * k
        log.robots.append(np.array([x, 0.0, 1.0, 0.0, 0.25, 2.0, 0.0, 1.0, 0.0]))
        log.humans.append(np.array([[x, -10.0, 0.0, 0.0, 0.3]]))
        log.times.append(0.1 * k)
        log.rewards.append(-0.25 if k == collide_at else 0.0)
    return log


def test_monte_carlo_targets_toward_a_fixed_local_goal():
    gamma = 0.9
    feats, y = targets(_straight_log(30, "timeout"), gamma, False, None, None)
    assert len(feats) == 30 and feats[0].shape == (1, 13)
    # Tick 0 reaches x > 1.75 (within the radius of the goal) at tick 18: reward +1 of the
    # transition from tick 17, discounted by γ^(1.7 s · 1 m/s).
    assert y[0] == pytest.approx(gamma ** 1.7)
    # A collision before the goal is reached: only the discounted penalty.
    _, yc = targets(_straight_log(10, "collision", collide_at=9), gamma, False, None, None)
    assert yc[0] == pytest.approx(-0.25 * gamma ** 0.9)
    # n-step: beyond n ticks the target network's value of the later state (same goal).
    _, yn = targets(_straight_log(30, "timeout"), gamma, False, 5,
                    lambda states: np.full(len(states), 0.5))
    assert yn[0] == pytest.approx(gamma ** 0.5 * 0.5)


def test_tiny_training_run_is_deterministic(tmp_path):
    cfg = load_config(None, [
        "robot=jackal", "map={type: empty, width: 8, height: 8}",
        "task.obstacles.static=0", "task.obstacles.dynamic=2",
        "task.robots.min_goal_distance=3", "task.timeout=3", "output.video=false",
    ])
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(cfg.model_dump(mode="json")))
    settings = TrainSettings(policy="sarl", config=str(path), seed=3, il_episodes=1,
                             il_epochs=1, rl_episodes=2, eps_decay=2, n_step=5,
                             train_batches=2, batch_size=16, target_update=1)
    a = train(settings, tmp_path / "a", log=lambda _: None)
    b = train(settings, tmp_path / "b", log=lambda _: None)
    pa, pb = load_value_policy(a), load_value_policy(b)
    for name, mlp in pa.network.modules.items():
        for wa, wb in zip(mlp.weights, pb.network.modules[name].weights, strict=True):
            np.testing.assert_array_equal(wa, wb)
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["il"]["episodes"] == 1 and summary["rl"]["episodes"] == 2
    assert summary["il"]["samples"] > 0
    assert pa.meta["training"]["settings"]["seed"] == 3
    assert (tmp_path / "a" / "log.csv").read_text().count("\n") == 3
